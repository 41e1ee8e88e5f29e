#pragma once
// SVG drawing primitives of the pictures (plots.cpp): numbers, text, paths of shapes in world
// coordinates, ellipses, arrows, and the time-series panel. Internal, not installed.
#include <pushgraph/evaluation/plots.h>
#include <pushgraph/geometry/pose.h>
#include <pushgraph/geometry/shape.h>

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace pushgraph::evaluation::svg {

using geometry::Pose2;
using geometry::Vec2;

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
inline constexpr const char* kFont = "font-family='DejaVu Sans, Helvetica, Arial, sans-serif'";

// Palette after the paper's Fig. 6: measured pink, estimated blue, ground truth black.
inline constexpr const char* kMeasuredColor = "#d6449a";
inline constexpr const char* kEstimatedColor = "#1f5fa8";
inline constexpr const char* kTruthColor = "#222222";
inline constexpr const char* kFingerColor = "#7f7f7f";
// One colour per finger k >= 1 of a push with several (finger 0 is each picture's own grey).
inline constexpr const char* kOtherFingerColors[] = {"#2ca02c", "#9467bd", "#17becf", "#8c564b", "#bcbd22"};
inline const char* OtherFingerColor(int k) { return kOtherFingerColors[(k - 1) % 5]; }
inline constexpr const char* kContactColor = "#e07b00";
inline constexpr const char* kForceColor = "#c0282d";
// Series colours of the time-series plot (raw first: pink like the measured dots).
inline constexpr const char* kSeriesColors[] = {"#d6449a", "#2ca02c", "#9467bd", "#1f5fa8", "#e07b00", "#17becf", "#8c564b"};

/// A coordinate with two decimals; text with XML's special characters escaped.
std::string Num(double v);
std::string Escape(const std::string& text);
/// A "nice" number (1, 2 or 5 times a power of ten) near x (Heckbert, Graphics Gems I, 1990);
/// the largest nice number at most x; a tick's label ("%g").
double NiceNumber(double x, bool round);
double NiceFloor(double x);
std::string TickLabel(double v);

struct Bounds {
  double xmin = std::numeric_limits<double>::infinity(), xmax = -xmin, ymin = xmin, ymax = -xmin;
  void Add(const Vec2& p) {
    if (!std::isfinite(p.x()) || !std::isfinite(p.y())) return;
    xmin = std::min(xmin, p.x());
    xmax = std::max(xmax, p.x());
    ymin = std::min(ymin, p.y());
    ymax = std::max(ymax, p.y());
  }
  bool empty() const { return !(xmax >= xmin); }
};


/// The sampled boundary of a rounded ring, and a shape's rings placed at `pose` (world).
std::vector<Vec2> RoundedRing(const geometry::Ring& ring, double r);
std::vector<std::vector<Vec2>> WorldRings(const geometry::Shape& shape, const Pose2& pose);

struct WorldView {
  double scale = 1.0;  // px per metre
  double x0 = 0.0, y0 = 0.0;  // pixel position of the world point (xmin, ymax)
  double xmin = 0.0, ymax = 0.0;
  double X(double x) const { return x0 + (x - xmin) * scale; }
  double Y(double y) const { return y0 + (ymax - y) * scale; }
  std::string P(const Vec2& p) const { return Num(X(p.x())) + "," + Num(Y(p.y())); }
};


/// The equal-aspect view of `bounds` in a box at most max_width x max_height pixels whose top
/// left corner is (x0, y0).
inline WorldView FitView(const Bounds& bounds, double max_width, double max_height, double x0, double y0) {
  WorldView view;
  view.scale = std::min(max_width / (bounds.xmax - bounds.xmin), max_height / (bounds.ymax - bounds.ymin));
  view.xmin = bounds.xmin;
  view.ymax = bounds.ymax;
  view.x0 = x0;
  view.y0 = y0;
  return view;
}

/// Closed rings as one SVG path; a polyline broken where consecutive times are over max_gap apart.
std::string RingsPath(const std::vector<std::vector<Vec2>>& rings, const WorldView& view);
std::string PolylinePath(const std::vector<double>& t, const std::vector<Vec2>& points, double max_gap,
                         const WorldView& view);
/// The median positive step of a time stamp list (infinity with fewer than two).
double MedianStep(const std::vector<double>& t);

/// Two-sigma ellipse of a 2x2 position covariance; empty when the covariance is unusable.
std::string Ellipse(const Eigen::Matrix2d& cov, const Vec2& centre, const WorldView& view, const std::string& cls,
                    const std::string& style);
/// An arrow from (x0, y0) to (x1, y1) (pixels) as one path: shaft and filled head.
std::string Arrow(double x0, double y0, double x1, double y1, const std::string& cls, const std::string& color,
                  double width, const std::string& extra = "");
std::string Text(double x, double y, const std::string& text, int size = 13, const std::string& anchor = "start",
                 const std::string& extra = "");
std::string SvgOpen(double width, double height);
/// Windows in which a stream has no samples (gaps over 3 median periods).
std::vector<std::pair<double, double>> StreamGaps(const std::vector<double>& t);
/// The time-series panel drawn into the box (x, y, width, height) of a larger picture.
std::string TimeSeriesPanel(const std::vector<TimeSeries>& series, const std::string& title,
                            const std::string& y_label, const std::vector<std::pair<double, double>>& shaded,
                            double x, double y, double width, double height);

}  // namespace pushgraph::evaluation::svg
