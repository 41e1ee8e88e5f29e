// SVG pictures of pushes and estimates (plots.h), drawn with svg.h's primitives.
#include "svg.h"

#include <pushgraph/geometry/file_output.h>
#include <pushgraph/evaluation/plots.h>
#include <pushgraph/io/trajectory_json.h>
#include <pushgraph/push/scoring.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>

namespace pushgraph::evaluation {
namespace {

using namespace svg;

Pose2 InterpolatePose(const std::vector<push::PoseSample>& samples, double t) {
  return push::PoseAtClamped(samples.begin(), samples.end(), t);
}

// The sample of a stream nearest in time to t, if one lies within `tolerance`.
template <class Sample>
const Sample* Nearest(const std::vector<Sample>& samples, double t, double tolerance) {
  auto it = std::lower_bound(samples.begin(), samples.end(), t,
                             [](const Sample& s, double time) { return s.t < time; });
  const Sample* best = nullptr;
  double best_dt = tolerance;
  for (auto c : {it, it == samples.begin() ? it : it - 1}) {
    if (c == samples.end()) continue;
    const double dt = std::abs(c->t - t);
    if (dt <= best_dt) best_dt = dt, best = &*c;
  }
  return best;
}


std::string ModelLabel(const graph::EstimationResult& result) {
  std::string name = graph::ModelName(result.model);
  std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return std::toupper(c); });
  return name;
}

// One entry of the trajectory plot's legend: a drawn sample (in a 28 x 14 box) and its text.
struct LegendEntry {
  std::string sample;  // SVG drawn relative to (0, 0) = left, middle of the sample box
  std::string text;
};

}  // namespace

std::string TrajectorySvg(const push::Trajectory& trajectory, const graph::EstimationResult& result,
                          const TrajectoryPlotOptions& options) {
  if (result.states.empty()) throw EvaluationError("trajectory plot: the estimation result has no states");
  const std::vector<graph::StateEstimate>& states = result.states;
  const std::size_t n = states.size();
  const push::Streams& measured = trajectory.measured;
  const push::Streams* truth = trajectory.ground_truth ? &*trajectory.ground_truth : nullptr;
  const bool truth_poses = truth && !truth->object_pose.empty();

  // Marked steps: about 12 along the push; the last state is always marked.
  const int every = options.every > 0 ? options.every : std::max(1, static_cast<int>(std::lround(n / 12.0)));
  std::vector<std::size_t> marked;
  for (std::size_t i = 0; i < n; i += every) marked.push_back(i);
  if (marked.back() != n - 1 && n - 1 - marked.back() > static_cast<std::size_t>(every) / 2) marked.push_back(n - 1);

  // Extent of everything drawn, in metres.
  Bounds bounds;
  std::vector<std::vector<std::vector<Vec2>>> estimated_footprints, truth_footprints, finger_shapes;
  std::vector<int> finger_of_shape;  // which finger each of finger_shapes is
  for (std::size_t i : marked) {
    estimated_footprints.push_back(WorldRings(trajectory.object.shape, states[i].object_pose));
    finger_shapes.push_back(WorldRings(trajectory.finger.shape, states[i].finger_pose));
    finger_of_shape.push_back(0);
    // Every other finger (pushes with several) at its own estimated pose, in its own colour.
    for (const graph::FingerPoseEstimate& f : states[i].other_fingers)
      if (f.finger >= 1 && f.finger <= static_cast<int>(trajectory.extra_fingers.size())) {
        finger_shapes.push_back(WorldRings(trajectory.extra_fingers[f.finger - 1].finger.shape, f.pose));
        finger_of_shape.push_back(f.finger);
      }
    if (truth_poses) truth_footprints.push_back(WorldRings(trajectory.object.shape, InterpolatePose(truth->object_pose, states[i].t)));
  }
  for (const auto* set : {&estimated_footprints, &truth_footprints, &finger_shapes})
    for (const auto& rings : *set)
      for (const auto& ring : rings)
        for (const Vec2& p : ring) bounds.Add(p);
  for (const graph::StateEstimate& s : states) {
    bounds.Add(s.object_pose.translation());
    bounds.Add(s.finger_pose.translation());
    if (s.contact) bounds.Add(*s.contact);
    for (const graph::ContactEstimate& c : s.contacts) bounds.Add(c.point);
  }
  for (const auto& s : measured.object_pose) bounds.Add(s.pose.translation());
  for (const auto& s : measured.finger_pose) bounds.Add(s.pose.translation());
  if (truth)
    for (const auto& s : truth->object_pose) bounds.Add(s.pose.translation());
  if (bounds.empty()) bounds.Add(Vec2::Zero());
  double extent = std::max({bounds.xmax - bounds.xmin, bounds.ymax - bounds.ymin, 1e-3});

  // Force arrows: one mm-per-newton scale for the picture, a 1-2-5 value that draws the largest
  // force at about a tenth of the picture's extent (longer arrows pile up along the push).
  double max_force = 0.0;
  for (std::size_t i : marked)
    if (states[i].force) max_force = std::max(max_force, states[i].force->norm());
  for (const auto& s : measured.force) max_force = std::max(max_force, s.force.norm());
  if (truth)
    for (const auto& s : truth->force) max_force = std::max(max_force, s.force.norm());
  for (const push::ExtraFinger& e : trajectory.extra_fingers) {
    for (const auto& s : e.measured.force) max_force = std::max(max_force, s.force.norm());
    if (e.ground_truth)
      for (const auto& s : e.ground_truth->force) max_force = std::max(max_force, s.force.norm());
  }
  const bool draw_forces = options.forces && max_force > 0.0 && std::isfinite(max_force);
  const double mm_per_newton = draw_forces ? NiceFloor(0.12 * extent * 1e3 / max_force) : 0.0;
  const double m_per_newton = mm_per_newton * 1e-3;

  // Arrows: estimated at the estimated contact, measured at the measured contact (else the
  // estimated one), ground truth at the true contact; samples within half a marked interval.
  struct ArrowSpec {
    Vec2 from, force;
  };
  std::vector<ArrowSpec> arrows_estimated, arrows_measured, arrows_truth;
  if (draw_forces) {
    const double tolerance = 0.5 * std::max(1e-9, (states.back().t - states.front().t) / std::max<double>(1, n - 1));
    for (std::size_t i : marked) {
      const graph::StateEstimate& s = states[i];
      // Each contact's own force where a step has several (two contacts, several fingers).
      for (const graph::ContactEstimate& c : s.contacts)
        if (c.force) arrows_estimated.push_back({c.point, *c.force});
      if (s.contacts.empty() && s.force && s.contact) arrows_estimated.push_back({*s.contact, *s.force});
      if (const auto* f = Nearest(measured.force, s.t, tolerance); f && f->force.norm() > 0.0) {
        const auto* c = Nearest(measured.contact_point, s.t, tolerance);
        if (c) arrows_measured.push_back({c->point, f->force});
        else if (s.contact) arrows_measured.push_back({*s.contact, f->force});
      }
      if (truth) {
        const auto* f = Nearest(truth->force, s.t, tolerance);
        const auto* c = Nearest(truth->contact_point, s.t, tolerance);
        if (f && c && f->force.norm() > 0.0) arrows_truth.push_back({c->point, f->force});
      }
      // The other fingers' own sensors and truth, at their own contacts.
      for (const push::ExtraFinger& e : trajectory.extra_fingers) {
        const auto* f = Nearest(e.measured.force, s.t, tolerance);
        const auto* c = Nearest(e.measured.contact_point, s.t, tolerance);
        if (f && c && f->force.norm() > 0.0) arrows_measured.push_back({c->point, f->force});
        if (!e.ground_truth) continue;
        f = Nearest(e.ground_truth->force, s.t, tolerance);
        c = Nearest(e.ground_truth->contact_point, s.t, tolerance);
        if (f && c && f->force.norm() > 0.0) arrows_truth.push_back({c->point, f->force});
      }
    }
    for (const auto* set : {&arrows_estimated, &arrows_measured, &arrows_truth})
      for (const ArrowSpec& a : *set) bounds.Add(a.from + m_per_newton * a.force);
  }
  const double pad = 0.04 * std::max(bounds.xmax - bounds.xmin, bounds.ymax - bounds.ymin) + 1e-3;
  bounds.xmin -= pad, bounds.xmax += pad, bounds.ymin -= pad, bounds.ymax += pad;
  extent = std::max(bounds.xmax - bounds.xmin, bounds.ymax - bounds.ymin);

  // Layout: map (equal aspect) on the left, legend on the right, error panel below.
  const double width = std::max(480, options.width_px);
  const double legend_width = 270.0, margin_left = 58.0, margin_top = options.title.empty() ? 16.0 : 40.0;
  const double map_width_max = width - legend_width - margin_left - 10.0;
  const double map_height_max = 1.1 * width;
  const WorldView view = FitView(bounds, map_width_max, map_height_max, margin_left, margin_top);
  const double scale = view.scale;
  const double map_w = (bounds.xmax - bounds.xmin) * scale, map_h = (bounds.ymax - bounds.ymin) * scale;
  const double legend_x = margin_left + map_w + 22.0;

  const bool error_panel = options.error_panel && truth_poses;
  const std::vector<TimeSeries> errors =
      error_panel ? ObjectPositionErrorSeries(trajectory, {{ModelLabel(result), &result}}) : std::vector<TimeSeries>{};
  const double panel_height = 230.0;
  const double map_bottom = margin_top + map_h + 44.0;

  std::string body;
  if (!options.title.empty()) body += Text(width / 2.0, 26.0, options.title, 16, "middle", "font-weight='bold'");

  // Axis ticks in millimetres on the map's frame.
  body += "<rect x='" + Num(view.x0) + "' y='" + Num(view.y0) + "' width='" + Num(map_w) + "' height='" + Num(map_h) +
          "' fill='none' stroke='#999999'/>\n";
  const int tick_count = std::max(3, static_cast<int>(map_w / 110.0));
  const double tick_step_mm = NiceNumber(extent * 1e3 / tick_count, true);
  for (double v = std::ceil(bounds.xmin * 1e3 / tick_step_mm) * tick_step_mm; v <= bounds.xmax * 1e3; v += tick_step_mm) {
    const double px = view.X(v * 1e-3);
    body += "<line x1='" + Num(px) + "' y1='" + Num(view.y0 + map_h) + "' x2='" + Num(px) + "' y2='" +
            Num(view.y0 + map_h + 4.0) + "' stroke='#666666'/>\n";
    body += Text(px, view.y0 + map_h + 16.0, TickLabel(std::abs(v) < 1e-9 ? 0.0 : v), 10, "middle", "fill='#444444'");
  }
  for (double v = std::ceil(bounds.ymin * 1e3 / tick_step_mm) * tick_step_mm; v <= bounds.ymax * 1e3; v += tick_step_mm) {
    const double py = view.Y(v * 1e-3);
    body += "<line x1='" + Num(view.x0 - 4.0) + "' y1='" + Num(py) + "' x2='" + Num(view.x0) + "' y2='" + Num(py) +
            "' stroke='#666666'/>\n";
    body += Text(view.x0 - 6.0, py + 3.5, TickLabel(std::abs(v) < 1e-9 ? 0.0 : v), 10, "end", "fill='#444444'");
  }
  body += Text(view.x0 + map_w / 2.0, view.y0 + map_h + 32.0, "x [mm]", 11, "middle", "fill='#444444'");
  body += Text(14.0, view.y0 + map_h / 2.0, "y [mm]", 11, "middle",
               "fill='#444444' transform='rotate(-90 14 " + Num(view.y0 + map_h / 2.0) + ")'");

  // Footprints: estimated faint filled, ground truth dashed outline; finger shapes grey.
  body += "<g class='footprints'>\n";
  // Overlapping fills would pile up into a dark blot: only the last footprint is filled, the
  // others are outlines.
  for (std::size_t k = 0; k < estimated_footprints.size(); ++k) {
    const bool last = k + 1 == estimated_footprints.size();
    body += "<path class='footprint-estimated' d='" + RingsPath(estimated_footprints[k], view) + "' fill='" +
            kEstimatedColor + "' fill-opacity='" + (last ? "0.12" : "0") + "' fill-rule='evenodd' stroke='" +
            kEstimatedColor + "' stroke-opacity='" + (last ? "0.8" : "0.4") + "' stroke-width='" +
            (last ? "1.2" : "0.8") + "'/>\n";
  }
  for (const auto& rings : truth_footprints)
    body += "<path class='footprint-truth' d='" + RingsPath(rings, view) + "' fill='none' stroke='" + kTruthColor +
            "' stroke-opacity='0.45' stroke-width='0.7' stroke-dasharray='3 3'/>\n";
  body += "</g>\n";

  // Paths of the object's reference point and of the finger.
  auto times_points = [](const std::vector<push::PoseSample>& s) {
    std::pair<std::vector<double>, std::vector<Vec2>> out;
    for (const auto& p : s) out.first.push_back(p.t), out.second.push_back(p.pose.translation());
    return out;
  };
  std::vector<double> state_t;
  std::vector<Vec2> object_path, finger_path;
  for (const graph::StateEstimate& s : states) {
    state_t.push_back(s.t);
    object_path.push_back(s.object_pose.translation());
    finger_path.push_back(s.finger_pose.translation());
  }
  const double infinite_gap = std::numeric_limits<double>::infinity();
  if (truth_poses) {
    const auto [t, p] = times_points(truth->object_pose);
    body += "<path class='path-truth' d='" + PolylinePath(t, p, infinite_gap, view) + "' fill='none' stroke='" +
            kTruthColor + "' stroke-width='1.6' stroke-dasharray='6 4'/>\n";
  }
  if (truth && !truth->finger_pose.empty()) {
    const auto [t, p] = times_points(truth->finger_pose);
    body += "<path class='finger-path-truth' d='" + PolylinePath(t, p, infinite_gap, view) + "' fill='none' stroke='" +
            kTruthColor + "' stroke-opacity='0.6' stroke-width='1.2' stroke-dasharray='6 4'/>\n";
  }
  for (std::size_t k = 0; k < finger_shapes.size(); ++k)
    body += "<path class='finger' d='" + RingsPath(finger_shapes[k], view) + "' fill='" +
            (finger_of_shape[k] == 0 ? kFingerColor : OtherFingerColor(finger_of_shape[k])) +
            "' fill-opacity='0.35' fill-rule='evenodd' stroke='#555555' stroke-width='0.8'/>\n";
  body += "<path class='finger-path-estimated' d='" + PolylinePath(state_t, finger_path, infinite_gap, view) +
          "' fill='none' stroke='#555555' stroke-width='1.4'/>\n";
  for (std::size_t k = 0; k < trajectory.extra_fingers.size(); ++k) {
    std::vector<double> other_t;
    std::vector<Vec2> other_path;
    for (const graph::StateEstimate& s : states)
      for (const graph::FingerPoseEstimate& f : s.other_fingers)
        if (f.finger == static_cast<int>(k) + 1) other_t.push_back(s.t), other_path.push_back(f.pose.translation());
    if (!other_path.empty())
      body += "<path class='finger-path-estimated' d='" + PolylinePath(other_t, other_path, infinite_gap, view) +
              "' fill='none' stroke='" + OtherFingerColor(static_cast<int>(k) + 1) + "' stroke-width='1.4' stroke-dasharray='2 2'/>\n";
  }
  {
    std::string dots;
    for (const auto& s : measured.finger_pose)
      dots += "M" + view.P(s.pose.translation()) + " h0.01 ";
    if (!dots.empty())
      body += "<path class='finger-measured' d='" + dots + "' stroke='" + kMeasuredColor +
              "' stroke-opacity='0.5' stroke-width='2' stroke-linecap='round' fill='none'/>\n";
  }
  body += "<path class='path-estimated' d='" + PolylinePath(state_t, object_path, infinite_gap, view) +
          "' fill='none' stroke='" + kEstimatedColor + "' stroke-width='2'/>\n";
  for (const auto& s : measured.object_pose)
    body += "<circle class='object-measured' cx='" + Num(view.X(s.pose.x)) + "' cy='" + Num(view.Y(s.pose.y)) +
            "' r='2.2' fill='" + kMeasuredColor + "' fill-opacity='0.85'/>\n";

  // Estimated contact points at the marked steps, then ellipses and force arrows on top.
  for (std::size_t i : marked) {
    std::vector<Vec2> points;
    for (const graph::ContactEstimate& c : states[i].contacts) points.push_back(c.point);
    if (points.empty() && states[i].contact) points.push_back(*states[i].contact);
    for (const Vec2& c : points)
      body += "<circle class='contact-estimated' cx='" + Num(view.X(c.x())) + "' cy='" + Num(view.Y(c.y())) +
              "' r='2.4' fill='" + kContactColor + "'/>\n";
  }
  int ellipse_count = 0;
  if (options.ellipses) {
    const std::string object_style = std::string("fill='") + kEstimatedColor + "' fill-opacity='0.15' stroke='" +
                                     kEstimatedColor + "' stroke-width='1.2'";
    const std::string finger_style = "fill='#555555' fill-opacity='0.12' stroke='#333333' stroke-width='1'";
    const std::string contact_style = std::string("fill='") + kContactColor + "' fill-opacity='0.15' stroke='" +
                                      kContactColor + "' stroke-width='1.2'";
    for (std::size_t i : marked) {
      const graph::StateEstimate& s = states[i];
      std::string e;
      if (s.object_pose_cov)
        e += Ellipse(s.object_pose_cov->topLeftCorner<2, 2>(), s.object_pose.translation(), view, "ellipse-object",
                     object_style);
      if (s.finger_pose_cov)
        e += Ellipse(s.finger_pose_cov->topLeftCorner<2, 2>(), s.finger_pose.translation(), view, "ellipse-finger",
                     finger_style);
      if (s.contact_cov && s.contact) e += Ellipse(*s.contact_cov, *s.contact, view, "ellipse-contact", contact_style);
      ellipse_count += !e.empty();
      body += e;
    }
  }
  auto draw_arrows = [&](const std::vector<ArrowSpec>& arrows, const std::string& cls, const std::string& color,
                         double stroke, const std::string& extra) {
    for (const ArrowSpec& a : arrows) {
      const Vec2 to = a.from + m_per_newton * a.force;
      body += Arrow(view.X(a.from.x()), view.Y(a.from.y()), view.X(to.x()), view.Y(to.y()), cls, color, stroke, extra);
    }
  };
  draw_arrows(arrows_truth, "force-truth", kTruthColor, 1.2, "stroke-opacity='0.7' fill-opacity='0.7'");
  draw_arrows(arrows_measured, "force-measured", kMeasuredColor, 1.2, "stroke-opacity='0.8' fill-opacity='0.8'");
  draw_arrows(arrows_estimated, "force-estimated", kForceColor, 2.0, "");

  // Scale bar (mm), bottom left inside the map.
  {
    const double bar_mm = NiceFloor(0.2 * (bounds.xmax - bounds.xmin) * 1e3);
    const double bx = view.x0 + 12.0, by = view.y0 + map_h - 12.0, bw = bar_mm * 1e-3 * scale;
    body += "<rect x='" + Num(bx - 4.0) + "' y='" + Num(by - 20.0) + "' width='" + Num(bw + 8.0) +
            "' height='27' fill='white' fill-opacity='0.8'/>\n";
    body += "<path class='scale-bar' d='M" + Num(bx) + "," + Num(by - 4.0) + " V" + Num(by) + " H" + Num(bx + bw) +
            " V" + Num(by - 4.0) + "' fill='none' stroke='black' stroke-width='1.5'/>\n";
    body += Text(bx + bw / 2.0, by - 7.0, TickLabel(bar_mm) + " mm", 11, "middle");
  }

  // Legend.
  std::vector<LegendEntry> legend;
  const std::string dot = std::string("<circle cx='14' cy='0' r='2.6' fill='") + kMeasuredColor + "'/>";
  legend.push_back({dot, "object position, measured"});
  legend.push_back({std::string("<line x1='0' y1='0' x2='28' y2='0' stroke='") + kEstimatedColor +
                        "' stroke-width='2'/>",
                    "object position, " + ModelLabel(result) + " estimate"});
  if (truth_poses)
    legend.push_back({std::string("<line x1='0' y1='0' x2='28' y2='0' stroke='") + kTruthColor +
                          "' stroke-width='1.6' stroke-dasharray='6 4'/>",
                      "object position, ground truth"});
  legend.push_back({std::string("<rect x='2' y='-6' width='24' height='12' fill='none' stroke='") + kEstimatedColor +
                        "' stroke-opacity='0.6'/>",
                    "footprint at estimate (last filled)"});
  if (truth_poses)
    legend.push_back({std::string("<rect x='2' y='-6' width='24' height='12' fill='none' stroke='") + kTruthColor +
                          "' stroke-dasharray='4 3'/>",
                      "footprint, ground truth"});
  legend.push_back({"<circle cx='14' cy='0' r='5' fill='#7f7f7f' fill-opacity='0.35' stroke='#555555'/>"
                    "<line x1='0' y1='0' x2='8' y2='0' stroke='#555555' stroke-width='1.4'/>",
                    trajectory.extra_fingers.empty() ? "finger: shape, estimated path" : "finger 0: shape, estimated path"});
  for (std::size_t k = 1; k <= trajectory.extra_fingers.size(); ++k)
    legend.push_back({std::string("<circle cx='14' cy='0' r='5' fill='") + OtherFingerColor(static_cast<int>(k)) +
                          "' fill-opacity='0.35' stroke='#555555'/><line x1='0' y1='0' x2='8' y2='0' stroke='" +
                          OtherFingerColor(static_cast<int>(k)) + "' stroke-width='1.4' stroke-dasharray='2 2'/>",
                      "finger " + std::to_string(k)});
  if (std::any_of(marked.begin(), marked.end(), [&](std::size_t i) { return states[i].contact.has_value(); }))
    legend.push_back({std::string("<circle cx='14' cy='0' r='2.4' fill='") + kContactColor + "'/>",
                      "contact point, estimate"});
  if (ellipse_count > 0) {
    legend.push_back({std::string("<ellipse cx='14' cy='0' rx='12' ry='5' fill='") + kEstimatedColor +
                          "' fill-opacity='0.15' stroke='" + kEstimatedColor + "'/>",
                      "2-sigma ellipse (86.5%)"});
    legend.push_back({"", "  of object, finger, contact"});
  }
  if (!arrows_estimated.empty())
    legend.push_back({Arrow(0, 0, 28, 0, "legend", kForceColor, 2.0), "force, estimate"});
  if (!arrows_measured.empty())
    legend.push_back({Arrow(0, 0, 28, 0, "legend", kMeasuredColor, 1.2), "force, measured"});
  if (!arrows_truth.empty()) legend.push_back({Arrow(0, 0, 28, 0, "legend", kTruthColor, 1.2), "force, ground truth"});
  if (draw_forces && (arrows_estimated.size() + arrows_measured.size() + arrows_truth.size()) > 0)
    legend.push_back({"", "  arrows: 1 N = " + TickLabel(mm_per_newton) + " mm"});
  legend.push_back({"", "marks every " + std::to_string(every) + (every == 1 ? " step (" : " steps (") +
                            std::to_string(n) + (n == 1 ? " step)" : " steps)")});
  if (auto it = result.metrics.find("object_position_rms"); it != result.metrics.end()) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "object position RMS error: %.2f mm", it->second * 1e3);
    legend.push_back({"", buf});
    if (auto m = result.metrics.find("measured_object_position_rms"); m != result.metrics.end()) {
      std::snprintf(buf, sizeof buf, "  (measured: %.2f mm)", m->second * 1e3);
      legend.push_back({"", buf});
    }
  }
  double ly = view.y0 + 10.0;
  body += "<g class='legend-box'>\n";
  for (const LegendEntry& e : legend) {
    if (!e.sample.empty())
      body += "<g transform='translate(" + Num(legend_x) + "," + Num(ly) + ")'>" + e.sample + "</g>\n";
    body += Text(legend_x + 36.0, ly + 4.0, e.text, 12);
    ly += 20.0;
  }
  body += "</g>\n";

  double height = std::max(map_bottom, ly + 10.0);
  if (error_panel && !errors.empty()) {
    std::vector<double> object_t;
    for (const auto& s : measured.object_pose) object_t.push_back(s.t);
    body += TimeSeriesPanel(errors, "object position error", "error [mm]", StreamGaps(object_t), 0.0, height, width,
                            panel_height);
    height += panel_height;
  }
  return SvgOpen(width, height) + body + "</svg>\n";
}

void WriteSvgFile(const std::string& path, const std::string& svg) {
  if (const std::string error = geometry::WriteFileAtomically(path, svg); !error.empty()) throw EvaluationError(error);
}

void WriteTrajectorySvg(const std::string& path, const push::Trajectory& trajectory,
                        const graph::EstimationResult& result, const TrajectoryPlotOptions& options) {
  if (result.states.empty()) throw EvaluationError(path + ": cannot plot an estimation result without states");
  WriteSvgFile(path, TrajectorySvg(trajectory, result, options));
}

std::string TimeSeriesSvg(const std::vector<TimeSeries>& series, const std::string& title, const std::string& y_label,
                          const std::vector<std::pair<double, double>>& shaded) {
  const double width = 960.0, height = 300.0;
  return SvgOpen(width, height) + TimeSeriesPanel(series, title, y_label, shaded, 0.0, 0.0, width, height) + "</svg>\n";
}

std::vector<TimeSeries> ObjectPositionErrorSeries(
    const push::Trajectory& trajectory,
    const std::vector<std::pair<std::string, const graph::EstimationResult*>>& results) {
  std::vector<TimeSeries> series;
  if (!trajectory.ground_truth || trajectory.ground_truth->object_pose.empty()) return series;
  const auto& truth = trajectory.ground_truth->object_pose;
  // push/scoring.h's rule: no error where the truth has a gap (an occluded recording's hole).
  auto add = [&](TimeSeries& series, double t, const Vec2& p) {
    Eigen::Vector3d g;
    if (!push::TruthPoseAt(truth, t, &g)) return;
    series.t.push_back(t);
    series.value.push_back(1e3 * (p - g.head<2>()).norm());
  };
  TimeSeries raw{"raw", {}, {}};
  for (const auto& s : trajectory.measured.object_pose) add(raw, s.t, s.pose.translation());
  series.push_back(std::move(raw));
  for (const auto& [label, result] : results) {
    if (result == nullptr) throw EvaluationError("object position error: result '" + label + "' is null");
    TimeSeries s{label, {}, {}};
    for (const graph::StateEstimate& state : result->states) add(s, state.t, state.object_pose.translation());
    series.push_back(std::move(s));
  }
  return series;
}

std::string StackSvgVertically(const std::vector<std::string>& pictures) {
  double width = 0.0, height = 0.0;
  std::string body;
  for (const std::string& svg : pictures) {
    const std::size_t open = svg.find("<svg");
    const std::size_t open_end = svg.find('>', open);
    const std::size_t close = svg.rfind("</svg>");
    if (open == std::string::npos || open_end == std::string::npos || close == std::string::npos)
      throw EvaluationError("stacking SVG pictures: a picture is not an <svg> element");
    const std::string tag = svg.substr(open, open_end - open);
    auto attribute = [&](const std::string& name) {
      const std::size_t at = tag.find(" " + name + "='");
      if (at == std::string::npos) throw EvaluationError("stacking SVG pictures: a picture has no " + name);
      return std::stod(tag.substr(at + name.size() + 3));
    };
    const double w = attribute("width"), h = attribute("height");
    body += "<svg x='0' y='" + Num(height) + "' width='" + Num(w) + "' height='" + Num(h) + "' viewBox='0 0 " +
            Num(w) + " " + Num(h) + "'>\n" + svg.substr(open_end + 1, close - open_end - 1) + "</svg>\n";
    width = std::max(width, w);
    height += h;
  }
  return SvgOpen(width, height) + body + "</svg>\n";
}

}  // namespace pushgraph::evaluation

