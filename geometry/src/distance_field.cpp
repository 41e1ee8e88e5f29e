// Sampled signed-distance field: exact samples on a regular grid, bicubic interpolation
// (Keys' cubic convolution as implemented by ceres::BiCubicInterpolator), and a build-time
// measurement of the interpolation error against the exact query.
#include <pushgraph/geometry/distance_field.h>

#include <pushgraph/geometry/point_query.h>

#include <ceres/cubic_interpolation.h>

#include <algorithm>
#include <limits>
#include <cmath>
#include <cstdio>
#include <vector>

namespace pushgraph::geometry {

// Exact samples beyond the grid on every side, read only by the interpolation: Keys' kernel at a
// point of the last cell reads the samples one and two rows beyond it, which the interpolator
// otherwise takes as copies of the last row, flattening the gradient there (0.5 for 1.0 on the
// last row of a box; (0, 0) at a corner of a grid with margin 0).
constexpr int kPad = 2;

struct DistanceField::Impl {
  Box2 bounds;  // the grid's own nodes (without the padding)
  double h = 0.0;
  int rows = 0, cols = 0;
  std::vector<double> values;  // row-major, row = y index, padded: (rows + 2 kPad) x (cols + 2 kPad)
  std::unique_ptr<ceres::Grid2D<double, 1>> grid;
  std::unique_ptr<ceres::BiCubicInterpolator<ceres::Grid2D<double, 1>>> interpolator;
  double max_error = 0.0;
  Vec2 max_error_at{0, 0};

  double Interpolate(const Vec2& p, Vec2* gradient) const {
    const double r = (p.y() - bounds.min.y()) / h + kPad, c = (p.x() - bounds.min.x()) / h + kPad;
    double f = 0, dfdr = 0, dfdc = 0;
    interpolator->Evaluate(r, c, &f, &dfdr, &dfdc);
    if (gradient) *gradient = Vec2(dfdc / h, dfdr / h);
    return f;
  }
};

DistanceField::DistanceField(const Shape& shape, const Options& options) : impl_(std::make_unique<Impl>()) {
  if (!(options.resolution > 0.0) || !std::isfinite(options.resolution))
    throw GeometryError("distance field resolution must be finite and > 0");
  if (!(options.margin >= 0.0) || !std::isfinite(options.margin))
    throw GeometryError("distance field margin must be finite and >= 0");
  if (options.error_samples_per_cell < 0) throw GeometryError("error_samples_per_cell must be >= 0");
  Impl& m = *impl_;
  const Box2 b = shape.bounds();
  m.h = options.resolution;
  m.bounds.min = b.min - Vec2::Constant(options.margin);
  const Vec2 size = b.max - b.min + Vec2::Constant(2.0 * options.margin);
  m.cols = static_cast<int>(std::ceil(size.x() / m.h)) + 1;
  m.rows = static_cast<int>(std::ceil(size.y() / m.h)) + 1;
  const int stored_rows = m.rows + 2 * kPad, stored_cols = m.cols + 2 * kPad;
  if (static_cast<double>(stored_rows) * stored_cols > 5e7)
    throw GeometryError("distance field would have " + std::to_string(static_cast<double>(stored_rows) * stored_cols) +
                        " samples; use a coarser resolution");
  m.bounds.max = m.bounds.min + m.h * Vec2(m.cols - 1, m.rows - 1);
  m.values.resize(static_cast<std::size_t>(stored_rows) * stored_cols);
  // Node (i, j) of the grid (i, j from -kPad) in the padded storage.
  const auto at = [&](int i, int j) { return static_cast<std::size_t>(i + kPad) * stored_cols + (j + kPad); };
  // The closest feature of each sample: a cell whose corners disagree contains a kink of the
  // field (the medial axis), where interpolation errs most and the check samples densely.
  std::vector<long> feature(m.values.size());
  for (int i = -kPad; i < m.rows + kPad; ++i) {
    for (int j = -kPad; j < m.cols + kPad; ++j) {
      const PointQuery q = QueryPoint(shape, m.bounds.min + m.h * Vec2(j, i));
      const std::size_t k = at(i, j);
      m.values[k] = q.signed_distance;
      const EdgeId& e = q.feature.edge;
      feature[k] = ((static_cast<long>(e.polygon) * 65536 + e.ring + 1) * 1048576 + e.index) * 2 +
                   (q.feature.kind == BoundaryFeature::Kind::kEdge ? 1 : 0);
    }
  }
  m.grid = std::make_unique<ceres::Grid2D<double, 1>>(m.values.data(), 0, stored_rows, 0, stored_cols);
  m.interpolator = std::make_unique<ceres::BiCubicInterpolator<ceres::Grid2D<double, 1>>>(*m.grid);

  const int samples = options.error_samples_per_cell;
  // No check, no figure: a 0 read as "no error" (the field's true error was 9.4e-3 there).
  if (samples == 0) m.max_error = std::numeric_limits<double>::quiet_NaN();
  const auto is_kink = [&](int i, int j) {
    const long f = feature[at(i, j)];
    return f != feature[at(i, j + 1)] || f != feature[at(i + 1, j)] || f != feature[at(i + 1, j + 1)];
  };
  // Kink cells get 8 s + 1 samples per axis, but all of them together at most twice the plain
  // check's samples: a detailed outline (edges shorter than a cell) makes most cells near it kink
  // cells, and the check's cost must stay proportional to the grid.
  std::size_t kinks = 0;
  for (int i = 0; samples > 0 && i + 1 < m.rows; ++i)
    for (int j = 0; j + 1 < m.cols; ++j) kinks += is_kink(i, j) ? 1 : 0;
  const double cells = static_cast<double>(m.rows - 1) * (m.cols - 1);
  const int kink_samples =
      kinks == 0 ? samples
                 : std::clamp(static_cast<int>(std::sqrt(2.0 * cells * samples * samples / static_cast<double>(kinks))),
                              samples, 8 * samples + 1);
  for (int i = 0; samples > 0 && i + 1 < m.rows; ++i) {
    for (int j = 0; j + 1 < m.cols; ++j) {
      const int s = is_kink(i, j) ? kink_samples : samples;
      for (int a = 0; a < s; ++a) {
        for (int c = 0; c < s; ++c) {
          const Vec2 p = m.bounds.min + m.h * Vec2(j + (c + 0.5) / s, i + (a + 0.5) / s);
          const double err = std::abs(m.Interpolate(p, nullptr) - QueryPoint(shape, p).signed_distance);
          if (err > m.max_error) m.max_error = err, m.max_error_at = p;
        }
      }
    }
  }
}

DistanceField::~DistanceField() = default;
DistanceField::DistanceField(DistanceField&&) noexcept = default;
DistanceField& DistanceField::operator=(DistanceField&&) noexcept = default;

namespace {
// A moved-from field holds nothing: an error, not a null dereference.
void RequireHeld(const void* impl) {
  if (impl == nullptr) throw GeometryError("DistanceField: operation on a moved-from field");
}
}  // namespace

double DistanceField::Evaluate(const Vec2& point, Vec2* gradient) const {
  RequireHeld(impl_.get());
  const Impl& m = *impl_;
  if (!std::isfinite(point.x()) || !std::isfinite(point.y())) throw GeometryError("distance field query point is not finite");
  // The exact query's bound: beyond it the continuation's squared distances overflow (inf at 1e154).
  if (std::abs(point.x()) > kMaxQueryCoordinate || std::abs(point.y()) > kMaxQueryCoordinate) {
    char text[160];
    std::snprintf(text, sizeof text, "distance field query point (%g, %g) is beyond %g, the query coordinates' bound", point.x(),
                  point.y(), kMaxQueryCoordinate);
    throw GeometryError(text);
  }
  const Vec2 clamped = point.cwiseMax(m.bounds.min).cwiseMin(m.bounds.max);
  if (clamped == point) return m.Interpolate(point, gradient);
  // Outside the grid: value at the nearest grid point plus the distance to it (1-Lipschitz, so
  // never below the true signed distance by more than the grid's own error).
  const Vec2 offset = point - clamped;
  const double extra = offset.norm();
  const double inner = m.Interpolate(clamped, nullptr);
  if (gradient) *gradient = offset / extra;
  return inner + extra;
}

double DistanceField::max_error() const { return (RequireHeld(impl_.get()), impl_->max_error); }
Vec2 DistanceField::max_error_location() const { return (RequireHeld(impl_.get()), impl_->max_error_at); }
int DistanceField::rows() const { return (RequireHeld(impl_.get()), impl_->rows); }
int DistanceField::cols() const { return (RequireHeld(impl_.get()), impl_->cols); }
Box2 DistanceField::grid_bounds() const { return (RequireHeld(impl_.get()), impl_->bounds); }

}  // namespace pushgraph::geometry
