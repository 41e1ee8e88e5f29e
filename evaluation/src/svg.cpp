// SVG drawing primitives (svg.h). Plain string building: no drawing library, the output is small
// hand-readable SVG 1.1 that browsers and rsvg-convert render alike.
#include "svg.h"

#include <Eigen/Eigenvalues>

#include <cstdio>

namespace pushgraph::evaluation::svg {

// A "nice" number (1, 2 or 5 times a power of ten) near `x` (Heckbert, Graphics Gems I, 1990).
double NiceNumber(double x, bool round) {
  if (!(x > 0.0) || !std::isfinite(x)) return 1.0;
  const double exponent = std::floor(std::log10(x));
  const double fraction = x / std::pow(10.0, exponent);
  double nice;
  if (round) nice = fraction < 1.5 ? 1 : fraction < 3 ? 2 : fraction < 7 ? 5 : 10;
  else nice = fraction <= 1 ? 1 : fraction <= 2 ? 2 : fraction <= 5 ? 5 : 10;
  return nice * std::pow(10.0, exponent);
}

// The largest 1-2-5 value not above x.
double NiceFloor(double x) {
  if (!(x > 0.0) || !std::isfinite(x)) return 1.0;
  const double exponent = std::floor(std::log10(x));
  const double fraction = x / std::pow(10.0, exponent);
  const double nice = fraction >= 5 ? 5 : fraction >= 2 ? 2 : 1;
  return nice * std::pow(10.0, exponent);
}

static std::vector<double> Ticks(double lo, double hi, int target_count) {
  const double step = NiceNumber((hi - lo) / std::max(1, target_count), true);
  std::vector<double> ticks;
  for (double v = std::ceil(lo / step - 1e-9) * step; v <= hi + 1e-9 * step; v += step)
    ticks.push_back(std::abs(v) < 1e-12 * step ? 0.0 : v);
  return ticks;
}

std::string TickLabel(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

static double Cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }


std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", v);
  return buf;
}

std::string Escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '\'': out += "&apos;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

// The boundary of a rounded ring (every point within r of it), sampled: offset edges joined by
// circular arcs (at most 10 degrees per segment) at convex corners and by the offset lines'
// intersection at reflex corners (exact while edges are longer than the rounding, as in every
// shipped shape). Rings keep the shape's convention: interior on the left, so the offset side is
// the right-hand normal for outer boundaries and holes alike.
std::vector<Vec2> RoundedRing(const geometry::Ring& ring, double r) {
  const std::size_t n = ring.size();
  if (r <= 0.0) return ring;
  std::vector<Vec2> out;
  auto arc = [&](const Vec2& centre, double a0, double sweep) {
    const int segments = std::max(1, static_cast<int>(std::ceil(std::abs(sweep) / (M_PI / 18.0))));
    for (int k = 0; k <= segments; ++k) {
      const double a = a0 + sweep * k / segments;
      out.push_back(centre + r * Vec2(std::cos(a), std::sin(a)));
    }
  };
  if (n == 1) {
    arc(ring[0], 0.0, 2.0 * M_PI);
    out.pop_back();
    return out;
  }
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2& prev = ring[(i + n - 1) % n];
    const Vec2& v = ring[i];
    const Vec2& next = ring[(i + 1) % n];
    const Vec2 d0 = (v - prev).normalized(), d1 = (next - v).normalized();
    const Vec2 n0(d0.y(), -d0.x()), n1(d1.y(), -d1.x());
    const double turn = std::atan2(Cross(d0, d1), d0.dot(d1));  // > 0: convex corner (interior on the left)
    if (n == 2 || turn > 0.0) {
      arc(v, std::atan2(n0.y(), n0.x()), n == 2 ? M_PI : turn);
    } else if (1.0 + n0.dot(n1) > 0.1) {
      out.push_back(v + r * (n0 + n1) / (1.0 + n0.dot(n1)));
    } else {  // a needle-sharp reflex corner: keep both offset points rather than a far miter
      out.push_back(v + r * n0);
      out.push_back(v + r * n1);
    }
  }
  return out;
}

// Boundary rings (world frame) of a shape at a pose: outer boundaries and holes, rounding sampled.
std::vector<std::vector<Vec2>> WorldRings(const geometry::Shape& shape, const Pose2& pose) {
  std::vector<std::vector<Vec2>> rings;
  if (shape.empty()) return rings;
  const Eigen::Matrix2d R = pose.rotation();
  const Vec2 t = pose.translation();
  auto add = [&](const geometry::Ring& ring) {
    std::vector<Vec2> world = RoundedRing(ring, shape.radius());
    for (Vec2& p : world) p = R * p + t;
    rings.push_back(std::move(world));
  };
  for (const geometry::Polygon& polygon : shape.polygons()) {
    add(polygon.outer);
    for (const geometry::Ring& hole : polygon.holes) add(hole);
  }
  return rings;
}

// World (metres) to picture (pixels): equal aspect, y up.
std::string RingsPath(const std::vector<std::vector<Vec2>>& rings, const WorldView& view) {
  std::string d;
  for (const auto& ring : rings) {
    if (ring.size() < 2) continue;
    for (std::size_t i = 0; i < ring.size(); ++i) d += (i == 0 ? "M" : "L") + view.P(ring[i]) + " ";
    if (ring.size() > 2) d += "Z ";
  }
  return d;
}

// Polyline path through the points, broken (new "M") wherever consecutive times are further apart
// than `max_gap` (a tracking loss is shown as a gap, not as a straight line across it).
std::string PolylinePath(const std::vector<double>& t, const std::vector<Vec2>& points, double max_gap,
                         const WorldView& view) {
  std::string d;
  bool pen_down = false;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!std::isfinite(points[i].x()) || !std::isfinite(points[i].y())) {
      pen_down = false;
      continue;
    }
    if (i > 0 && t[i] - t[i - 1] > max_gap) pen_down = false;
    d += (pen_down ? "L" : "M") + view.P(points[i]) + " ";
    pen_down = true;
  }
  return d;
}

double MedianStep(const std::vector<double>& t) {
  std::vector<double> steps;
  for (std::size_t i = 1; i < t.size(); ++i)
    if (t[i] > t[i - 1]) steps.push_back(t[i] - t[i - 1]);
  if (steps.empty()) return std::numeric_limits<double>::infinity();
  std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
  return steps[steps.size() / 2];
}

// Two-sigma ellipse of a 2x2 position covariance: semi-axes 2 sqrt(eigenvalue) along the
// eigenvectors (the 86.5% contour of a 2-D Gaussian). Empty when the covariance is unusable.
std::string Ellipse(const Eigen::Matrix2d& cov, const Vec2& centre, const WorldView& view, const std::string& cls,
                    const std::string& style) {
  if (!cov.allFinite()) return "";
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(0.5 * (cov + cov.transpose()));
  if (eig.info() != Eigen::Success) return "";
  const Eigen::Vector2d lambda = eig.eigenvalues().cwiseMax(0.0);
  const Eigen::Vector2d major = eig.eigenvectors().col(1);
  const double rx = std::max(2.0 * std::sqrt(lambda(1)) * view.scale, 0.3);
  const double ry = std::max(2.0 * std::sqrt(lambda(0)) * view.scale, 0.3);
  // Picture y points down: a world angle a is -a on screen.
  const double angle_deg = -std::atan2(major.y(), major.x()) * 180.0 / M_PI;
  const double cx = view.X(centre.x()), cy = view.Y(centre.y());
  return "<ellipse class='" + cls + "' cx='" + Num(cx) + "' cy='" + Num(cy) + "' rx='" + Num(rx) + "' ry='" +
         Num(ry) + "' transform='rotate(" + Num(angle_deg) + " " + Num(cx) + " " + Num(cy) + ")' " + style + "/>\n";
}

// An arrow from `from` to `to` (pixels) as one path: shaft and filled head.
std::string Arrow(double x0, double y0, double x1, double y1, const std::string& cls, const std::string& color,
                  double width, const std::string& extra) {
  const double dx = x1 - x0, dy = y1 - y0, length = std::hypot(dx, dy);
  if (!(length > 0.5)) return "";
  const double ux = dx / length, uy = dy / length;
  const double head = std::min(9.0, 0.45 * length), half = 0.4 * head;
  const double bx = x1 - head * ux, by = y1 - head * uy;
  std::string d = "M" + Num(x0) + "," + Num(y0) + " L" + Num(bx) + "," + Num(by) + " M" + Num(x1) + "," + Num(y1) +
                  " L" + Num(bx - half * uy) + "," + Num(by + half * ux) + " L" + Num(bx + half * uy) + "," +
                  Num(by - half * ux) + " Z";
  return "<path class='" + cls + "' d='" + d + "' stroke='" + color + "' fill='" + color + "' stroke-width='" +
         Num(width) + "' " + extra + "/>\n";
}

std::string Text(double x, double y, const std::string& text, int size, const std::string& anchor,
                 const std::string& extra) {
  return "<text x='" + Num(x) + "' y='" + Num(y) + "' font-size='" + std::to_string(size) + "' text-anchor='" +
         anchor + "' " + kFont + " " + extra + ">" + Escape(text) + "</text>\n";
}

std::string SvgOpen(double width, double height) {
  return "<?xml version='1.0' encoding='UTF-8'?>\n<svg xmlns='http://www.w3.org/2000/svg' version='1.1' width='" +
         Num(width) + "' height='" + Num(height) + "' viewBox='0 0 " + Num(width) + " " + Num(height) +
         "'>\n<rect x='0' y='0' width='" + Num(width) + "' height='" + Num(height) + "' fill='white'/>\n";
}

// Time windows in which a stream has no samples although its neighbours are close: gaps longer
// than 3 median sample periods (the object tracker losing the object).
std::vector<std::pair<double, double>> StreamGaps(const std::vector<double>& t) {
  std::vector<std::pair<double, double>> gaps;
  const double step = MedianStep(t);
  if (!std::isfinite(step)) return gaps;
  for (std::size_t i = 1; i < t.size(); ++i)
    if (t[i] - t[i - 1] > 3.0 * step) gaps.emplace_back(t[i - 1], t[i]);
  return gaps;
}

// The time-series panel drawn into the box (x, y, width, height) of a larger picture.
std::string TimeSeriesPanel(const std::vector<TimeSeries>& series, const std::string& title,
                            const std::string& y_label, const std::vector<std::pair<double, double>>& shaded,
                            double x, double y, double width, double height) {
  std::string svg;
  const double legend_width = 170.0;
  const double left = x + 62.0, right = x + width - legend_width, top = y + 30.0, bottom = y + height - 42.0;
  double tmin = std::numeric_limits<double>::infinity(), tmax = -tmin, vmax = 0.0;
  for (const TimeSeries& s : series) {
    for (std::size_t i = 0; i < s.t.size() && i < s.value.size(); ++i) {
      if (!std::isfinite(s.t[i]) || !std::isfinite(s.value[i])) continue;
      tmin = std::min(tmin, s.t[i]);
      tmax = std::max(tmax, s.t[i]);
      vmax = std::max(vmax, s.value[i]);
    }
  }
  for (const auto& [t0, t1] : shaded) {
    if (std::isfinite(t0)) tmin = std::min(tmin, t0);
    if (std::isfinite(t1)) tmax = std::max(tmax, t1);
  }
  if (!(tmax >= tmin)) tmin = 0.0, tmax = 1.0;
  if (tmax == tmin) tmax = tmin + 1.0;
  // Unix time stamps (MIT recordings): at 1.46e9 s every tick would read the same; plot the time
  // since the first sample and say so in the title.
  if (std::abs(tmin) > 1e3 && std::abs(tmin) > 1e4 * (tmax - tmin)) {
    std::vector<TimeSeries> shifted = series;
    for (TimeSeries& s : shifted) {
      for (double& t : s.t) t -= tmin;
    }
    std::vector<std::pair<double, double>> windows = shaded;
    for (auto& w : windows) w = {w.first - tmin, w.second - tmin};
    char origin[64];
    std::snprintf(origin, sizeof origin, " (time from t0 = %.3f s)", tmin);
    return TimeSeriesPanel(shifted, title + origin, y_label, windows, x, y, width, height);
  }
  double vmin = 0.0;
  for (const TimeSeries& s : series)
    for (double v : s.value)
      if (std::isfinite(v)) vmin = std::min(vmin, v);
  if (!(vmax > vmin)) vmax = vmin + 1.0;
  // The top of the axis is the first tick above the data plus 5% headroom.
  const double ystep = NiceNumber((1.05 * vmax - vmin) / 5.0, true);
  vmax = std::ceil(1.05 * vmax / ystep - 1e-9) * ystep;
  vmin = std::floor(vmin / ystep + 1e-9) * ystep;
  std::vector<double> yticks;
  for (double v = vmin; v <= vmax + 1e-9 * ystep; v += ystep) yticks.push_back(std::abs(v) < 1e-12 * ystep ? 0.0 : v);
  const std::vector<double> xticks = Ticks(tmin, tmax, 8);
  auto X = [&](double t) { return left + (t - tmin) / (tmax - tmin) * (right - left); };
  auto Y = [&](double v) { return bottom - (v - vmin) / (vmax - vmin) * (bottom - top); };

  svg += Text(x + width / 2.0 - legend_width / 2.0, y + 19.0, title, 15, "middle", "font-weight='bold'");
  for (const auto& [t0, t1] : shaded) {
    const double a = X(std::max(t0, tmin)), b = X(std::min(t1, tmax));
    if (b > a)
      svg += "<rect class='shaded' x='" + Num(a) + "' y='" + Num(top) + "' width='" + Num(b - a) + "' height='" +
             Num(bottom - top) + "' fill='#cccccc' fill-opacity='0.45'/>\n";
  }
  for (double v : yticks) {
    svg += "<line x1='" + Num(left) + "' y1='" + Num(Y(v)) + "' x2='" + Num(right) + "' y2='" + Num(Y(v)) +
           "' stroke='#e4e4e4'/>\n";
    svg += Text(left - 6.0, Y(v) + 4.0, TickLabel(v), 11, "end");
  }
  for (double t : xticks) {
    svg += "<line x1='" + Num(X(t)) + "' y1='" + Num(bottom) + "' x2='" + Num(X(t)) + "' y2='" + Num(bottom + 4.0) +
           "' stroke='black'/>\n";
    svg += Text(X(t), bottom + 17.0, TickLabel(t), 11, "middle");
  }
  svg += "<rect x='" + Num(left) + "' y='" + Num(top) + "' width='" + Num(right - left) + "' height='" +
         Num(bottom - top) + "' fill='none' stroke='black'/>\n";
  svg += Text((left + right) / 2.0, bottom + 34.0, "time [s]", 12, "middle");
  svg += Text(x + 16.0, (top + bottom) / 2.0, y_label, 12, "middle",
              "transform='rotate(-90 " + Num(x + 16.0) + " " + Num((top + bottom) / 2.0) + ")'");

  double legend_y = top + 8.0;
  for (std::size_t k = 0; k < series.size(); ++k) {
    const TimeSeries& s = series[k];
    const std::string color = kSeriesColors[k % (sizeof kSeriesColors / sizeof *kSeriesColors)];
    const double max_gap = 3.0 * MedianStep(s.t);
    std::string d;
    bool pen_down = false;
    for (std::size_t i = 0; i < s.t.size() && i < s.value.size(); ++i) {
      if (!std::isfinite(s.t[i]) || !std::isfinite(s.value[i])) {
        pen_down = false;
        continue;
      }
      if (i > 0 && s.t[i] - s.t[i - 1] > max_gap) pen_down = false;
      d += (pen_down ? "L" : "M") + Num(X(s.t[i])) + "," + Num(Y(s.value[i])) + " ";
      pen_down = true;
    }
    const bool raw = k == 0 && (s.label == "raw" || s.label == "measured");
    // Every other estimate dashed, so that coinciding curves stay visible.
    const std::string dash = k >= 2 && k % 2 == 0 ? " stroke-dasharray='7 4'" : "";
    svg += "<path class='series' d='" + d + "' fill='none' stroke='" + color + "' stroke-width='" +
           (raw ? "1.2" : "1.8") + "' stroke-linejoin='round'" + (raw ? " stroke-opacity='0.8'" : "") + dash + "/>\n";
    svg += "<line x1='" + Num(right + 14.0) + "' y1='" + Num(legend_y) + "' x2='" + Num(right + 40.0) + "' y2='" +
           Num(legend_y) + "' stroke='" + color + "' stroke-width='2.5'" + dash + "/>\n";
    svg += Text(right + 46.0, legend_y + 4.0, s.label, 12);
    legend_y += 19.0;
  }
  if (!shaded.empty()) {
    svg += "<rect x='" + Num(right + 14.0) + "' y='" + Num(legend_y - 6.0) +
           "' width='26' height='12' fill='#cccccc' fill-opacity='0.6'/>\n";
    svg += Text(right + 46.0, legend_y + 4.0, "occlusion", 12);
  }
  return svg;
}


}  // namespace pushgraph::evaluation::svg
