// The picture of a push with every finger and contact (plots.h: PushSvg).
#include <pushgraph/evaluation/errors.h>
#include <pushgraph/evaluation/plots.h>

#include "svg.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

namespace pushgraph::evaluation {
using namespace svg;
namespace {

// One colour per finger (finger 0 the pictures' usual grey).
const char* FingerColor(int k) { return k == 0 ? "#555555" : OtherFingerColor(k); }

// One finger's streams, whichever struct holds them.
struct FingerView {
  const push::FingerDescription* finger;
  const std::vector<push::PoseSample>* pose;
  const std::vector<push::PointSample>* contact;
  const std::vector<push::ForceSample>* force;
};

template <class Sample>
const Sample* NearestSample(const std::vector<Sample>& samples, double t, double tolerance) {
  const Sample* best = nullptr;
  for (const Sample& s : samples)
    if (std::abs(s.t - t) <= tolerance && (!best || std::abs(s.t - t) < std::abs(best->t - t))) best = &s;
  return best;
}

}  // namespace

std::string PushSvg(const push::Trajectory& trajectory, const PushPlotOptions& options) {
  const bool truth = options.ground_truth && trajectory.ground_truth.has_value();
  const push::Streams& main = truth ? *trajectory.ground_truth : trajectory.measured;
  std::vector<FingerView> fingers{{&trajectory.finger, &main.finger_pose, &main.contact_point, &main.force}};
  for (const push::ExtraFinger& e : trajectory.extra_fingers) {
    const push::FingerStreams& s = truth && e.ground_truth ? *e.ground_truth : e.measured;
    fingers.push_back({&e.finger, &s.finger_pose, &s.contact_point, &s.force});
  }
  // Marked times: about options.marks of the object's samples.
  if (main.object_pose.empty())
    throw EvaluationError(std::string("push picture: the trajectory has no ") + (truth ? "ground-truth" : "measured") +
                          " object poses to draw");
  std::vector<double> times;
  for (const auto& s : main.object_pose) times.push_back(s.t);
  const int marks = std::max(2, options.marks);
  const std::size_t every = std::max<std::size_t>(1, times.size() / static_cast<std::size_t>(marks));
  std::vector<double> marked;
  for (std::size_t i = 0; i < times.size(); i += every) marked.push_back(times[i]);
  if (marked.back() != times.back()) marked.push_back(times.back());
  const double tolerance = 0.5 * MedianStep(times) + 1e-9;

  auto pose_at = [](const std::vector<push::PoseSample>& s, double t) { return push::PoseAtClamped(s.begin(), s.end(), t); };
  Bounds bounds;
  std::vector<std::vector<std::vector<Vec2>>> footprints;
  std::vector<std::vector<std::vector<std::vector<Vec2>>>> finger_shapes(fingers.size());
  for (double t : marked) {
    footprints.push_back(WorldRings(trajectory.object.shape, pose_at(main.object_pose, t)));
    for (std::size_t k = 0; k < fingers.size(); ++k)
      if (!fingers[k].pose->empty()) finger_shapes[k].push_back(WorldRings(fingers[k].finger->shape, pose_at(*fingers[k].pose, t)));
  }
  for (const auto& rings : footprints)
    for (const auto& ring : rings)
      for (const Vec2& p : ring) bounds.Add(p);
  for (const auto& per_finger : finger_shapes)
    for (const auto& rings : per_finger)
      for (const auto& ring : rings)
        for (const Vec2& p : ring) bounds.Add(p);

  // Contacts and forces at the marked times: every contact row within half a sample period; the
  // finger's force from the middle of its contacts (its pose when it touches nothing).
  struct Arrow2 {
    Vec2 from, force;
    int finger;
  };
  std::vector<std::pair<Vec2, int>> contacts;
  std::vector<Arrow2> arrows;
  int most_contacts = 0;
  double max_force = 0.0;
  for (double t : marked) {
    for (std::size_t k = 0; k < fingers.size(); ++k) {
      Vec2 middle = Vec2::Zero();
      int count = 0;
      double nearest_t = 0.0;
      if (const auto* c = NearestSample(*fingers[k].contact, t, tolerance)) nearest_t = c->t, count = -1;
      if (count == -1) {
        count = 0;
        for (const auto& c : *fingers[k].contact)
          if (c.t == nearest_t) contacts.push_back({c.point, static_cast<int>(k)}), middle += c.point, ++count;
        middle /= count;
        most_contacts = std::max(most_contacts, count);
      }
      if (const auto* f = NearestSample(*fingers[k].force, t, tolerance); f && f->force.norm() > 0.0 && count > 0) {
        arrows.push_back({middle, f->force, static_cast<int>(k)});
        max_force = std::max(max_force, f->force.norm());
      }
    }
  }
  if (bounds.empty()) bounds.Add(Vec2::Zero());
  const double extent = std::max({bounds.xmax - bounds.xmin, bounds.ymax - bounds.ymin, 1e-3});
  const double mm_per_newton = max_force > 0.0 ? NiceFloor(0.12 * extent * 1e3 / max_force) : 0.0;
  for (const Arrow2& a : arrows) bounds.Add(a.from + mm_per_newton * 1e-3 * a.force);
  const double pad = 0.04 * std::max(bounds.xmax - bounds.xmin, bounds.ymax - bounds.ymin) + 1e-3;
  bounds.xmin -= pad, bounds.xmax += pad, bounds.ymin -= pad, bounds.ymax += pad;

  const double width = std::max(480, options.width_px);
  const double legend_width = 300.0, margin_left = 20.0, margin_top = options.title.empty() ? 16.0 : 40.0;
  const WorldView view = FitView(bounds, width - legend_width - margin_left - 10.0, 1.1 * width, margin_left, margin_top);
  const double scale = view.scale;
  const double map_w = (bounds.xmax - bounds.xmin) * scale, map_h = (bounds.ymax - bounds.ymin) * scale;

  std::string body;
  if (!options.title.empty()) body += Text(margin_left, 24.0, options.title, 15, "start", "font-weight='bold'");
  for (std::size_t i = 0; i < footprints.size(); ++i) {
    const bool last = i + 1 == footprints.size();
    body += "<path class='footprint' d='" + RingsPath(footprints[i], view) + "' fill='" + kTruthColor + "' fill-opacity='" +
            (last ? "0.12" : "0") + "' fill-rule='evenodd' stroke='" + kTruthColor + "' stroke-opacity='" +
            (last ? "0.9" : "0.35") + "' stroke-width='1'/>\n";
  }
  const double infinite_gap = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < fingers.size(); ++k) {
    const std::string cls = "finger-" + std::to_string(k);
    for (const auto& rings : finger_shapes[k])
      body += "<path class='" + cls + "' d='" + RingsPath(rings, view) + "' fill='" + FingerColor(k) +
              "' fill-opacity='0.35' fill-rule='evenodd' stroke='" + FingerColor(k) + "' stroke-width='0.8'/>\n";
    // The path of the shape's middle (fingers of one pusher share its pose; their shapes differ).
    const geometry::Box2 box = fingers[k].finger->shape.bounds();
    const Vec2 middle = 0.5 * (box.min + box.max);
    std::vector<double> t;
    std::vector<Vec2> p;
    for (const auto& s : *fingers[k].pose) t.push_back(s.t), p.push_back(geometry::Act(s.pose, middle));
    if (!t.empty())
      body += "<path class='" + cls + "-path' d='" + PolylinePath(t, p, infinite_gap, view) + "' fill='none' stroke='" +
              FingerColor(k) + "' stroke-width='1.2'/>\n";
  }
  for (const auto& [point, k] : contacts)
    body += "<circle class='contact' cx='" + Num(view.X(point.x())) + "' cy='" + Num(view.Y(point.y())) + "' r='2.6' fill='" +
            kContactColor + "' stroke='" + FingerColor(k) + "' stroke-width='0.8'/>\n";
  for (const Arrow2& a : arrows) {
    const Vec2 to = a.from + mm_per_newton * 1e-3 * a.force;
    body += Arrow(view.X(a.from.x()), view.Y(a.from.y()), view.X(to.x()), view.Y(to.y()), "force-" + std::to_string(a.finger),
                  FingerColor(a.finger), 1.6);
  }
  // Scale bar.
  const double bar_mm = NiceFloor(0.2 * (bounds.xmax - bounds.xmin) * 1e3);
  const double bx = view.x0 + 12.0, by = view.y0 + map_h - 12.0, bw = bar_mm * 1e-3 * scale;
  body += "<path class='scale-bar' d='M" + Num(bx) + "," + Num(by - 4.0) + " V" + Num(by) + " H" + Num(bx + bw) + " V" +
          Num(by - 4.0) + "' fill='none' stroke='black' stroke-width='1.5'/>\n";
  body += Text(bx + bw / 2.0, by - 7.0, TickLabel(bar_mm) + " mm", 11, "middle");

  // Legend.
  const double legend_x = margin_left + map_w + 22.0;
  double ly = view.y0 + 10.0;
  auto entry = [&](const std::string& sample, const std::string& text) {
    if (!sample.empty()) body += "<g transform='translate(" + Num(legend_x) + "," + Num(ly) + ")'>" + sample + "</g>\n";
    body += Text(legend_x + 36.0, ly + 4.0, text, 12);
    ly += 20.0;
  };
  entry(std::string("<rect x='2' y='-6' width='24' height='12' fill='none' stroke='") + kTruthColor + "'/>",
        std::string("object, ") + (truth ? "ground truth" : "measured") + " (last filled)");
  for (std::size_t k = 0; k < fingers.size(); ++k)
    entry(std::string("<circle cx='14' cy='0' r='5' fill='") + FingerColor(k) + "' fill-opacity='0.35' stroke='" +
              FingerColor(k) + "'/>",
          "finger " + std::to_string(k) + ": shape, path, force");
  if (!contacts.empty())
    entry(std::string("<circle cx='14' cy='0' r='2.6' fill='") + kContactColor + "'/>",
          "contact points (" + std::to_string(contacts.size()) + " drawn)");
  if (most_contacts > 1) entry("", "  up to " + std::to_string(most_contacts) + " contacts of one finger at once");
  if (!arrows.empty()) entry("", "arrows: 1 N = " + TickLabel(mm_per_newton) + " mm");
  entry("", std::to_string(marked.size()) + " marked times of " + std::to_string(times.size()) + " samples");
  const double height = std::max(margin_top + map_h + 20.0, ly + 10.0);
  return SvgOpen(width, height) + body + "</svg>\n";
}

}  // namespace pushgraph::evaluation
