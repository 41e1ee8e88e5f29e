// Shape registration from recorded pushes (registration.h): smoothing, units and mirror
// candidates, a global search over rotations with robust Gauss-Newton over the translation,
// exact refinement with a calibration gap per recording, symmetry and observability, and the
// "does the shape fit as given" check.
#include <pushgraph/geometry/errors.h>
#include <pushgraph/geometry/point_query.h>
#include <pushgraph/geometry/shape_pair.h>
#include <pushgraph/graph/factors.h>
#include <pushgraph/graph/registration.h>

#include "contact_fit.h"
#include "graph_builder.h"
#include "text.h"

#include <ceres/ceres.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include <algorithm>
#include <iterator>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>

namespace pushgraph::graph {

using internal::Format;
using internal::Median;
using internal::WeightedMedian;
using namespace internal::registration;  // the contacts, ContactFit and helpers (contact_fit.h)

RegistrationOptions RegistrationOptionsFor(const EstimatorConfig& config) {
  RegistrationOptions o;
  o.contact_max_gap = config.contact_max_gap;
  o.contact_force_threshold = config.contact_force_threshold;
  o.contact_force_sigma = config.measurement.force;
  o.pose_sigma_trans = config.measurement.object_trans;
  o.pose_sigma_rot = config.measurement.object_rot;
  o.accel_trans = config.accel_trans;
  o.accel_rot = config.accel_rot;
  return o;
}

geometry::Shape RegistrationResult::Apply(const geometry::Shape& shape) const {
  if (transform.IsIdentity()) return shape;
  return geometry::TransformShape(shape, transform.pose, transform.scale, transform.mirrored);
}

std::string RegistrationResult::Describe() const {
  std::string s = Format("turned by %.1f deg, shifted by (%.1f, %.1f) mm", transform.pose.theta * 180.0 / kPi,
                         transform.pose.x * 1e3, transform.pose.y * 1e3);
  // How sure: one push often leaves the position along its side to the centroid prior, and
  // without the sigmas a placement 15 mm off read as exact.
  if (sigma.x() > 0.0 || sigma.y() > 0.0) {
    // A sigma of a half turn or more is no sigma (a strip of a side view read "sigma 680500 deg").
    const std::string turn = sigma.z() < kPi ? Format("%.1f deg", sigma.z() * 180.0 / kPi) : std::string("over 180 deg: the turn is not fixed");
    s += rotation_observable ? Format(" (sigma %s, %.1f and %.1f mm)", turn.c_str(), sigma.x() * 1e3, sigma.y() * 1e3)
                             : Format(" (sigma %.1f and %.1f mm)", sigma.x() * 1e3, sigma.y() * 1e3);
  }
  if (transform.mirrored) s = "mirrored (y -> -y), " + s;
  if (transform.scale != 1.0) {
    s += Format(", scale %.6g", transform.scale);
    const std::string unit = UnitPhrase(transform.scale);
    if (!unit.empty()) s += " (" + unit + ")";
  }
  if (!rotation_observable) s += "; rotation unobservable (circular outline)";
  return s;
}

std::string ShapeFitCheck::Describe() const {
  return Format("median contact gap %.1f mm, %.0f%% of the contact samples inside the shape by more than %.1f mm (%d samples)",
                gap_median * 1e3, penetration_share * 100.0, tolerance * 1e3, samples);
}

ShapeTransform CanonicalTransform(const ShapeTransform& transform, const geometry::Shape& file_shape, int symmetry_order) {
  ShapeTransform out = transform;
  out.pose.theta = geometry::WrapAngle(out.pose.theta);
  if (symmetry_order < 2) return out;
  // Turning the shape by m 2 pi / k about its centroid c leaves it unchanged:
  // T' = T * Rot_c(-m 2 pi / k), Rot_c(phi) = (c - R(phi) c, phi), c in scaled (mirrored) units.
  const double step = 2.0 * kPi / symmetry_order;
  const double turn = std::round(out.pose.theta / step) * step;
  Vec2 c = geometry::CoreCentroid(file_shape) * transform.scale;
  if (transform.mirrored) c.y() = -c.y();
  const Vec2 shift = Rotate(c - Rotate(c, -turn), out.pose.theta);
  out.pose = {out.pose.x + shift.x(), out.pose.y + shift.y(), geometry::WrapAngle(out.pose.theta - turn)};
  return out;
}

FingerDisk FingerAsDisk(const geometry::Shape& finger) {
  if (finger.empty()) throw GraphError("registration: the finger shape is empty");
  FingerDisk d;
  const auto& polys = finger.polygons();
  if (finger.is_degenerate_core() && polys.size() == 1 && polys[0].outer.size() == 1) {
    d.centre = polys[0].outer[0];
    d.radius = finger.radius();
    d.exact = true;
    return d;
  }
  d.centre = geometry::CoreCentroid(finger);
  const double outer = geometry::RadiusAbout(finger, d.centre);
  const double inner = finger.is_degenerate_core()
                           ? finger.radius()
                           : std::max(0.0, -geometry::QueryPoint(finger, d.centre).signed_distance);
  d.radius = 0.5 * (outer + inner);
  return d;
}

int OutlineSymmetryOrder(const geometry::Shape& shape, const geometry::Vec2& centre, double tolerance) {
  const Shape outline = OutlineOf(shape);
  const std::vector<Vec2> samples = OutlineSamples(shape);
  double rmin = INFINITY, rmax = 0.0;
  for (const Vec2& p : samples) {
    rmin = std::min(rmin, (p - centre).norm());
    rmax = std::max(rmax, (p - centre).norm());
  }
  if (rmax - rmin <= tolerance) return 0;
  for (int k = 12; k >= 2; --k) {
    bool symmetric = true;
    for (const Vec2& p : samples) {
      const Vec2 turned = centre + Rotate(p - centre, 2.0 * kPi / k);
      // Compare cores: the rounding radius is the same everywhere.
      if (std::abs(geometry::QueryPoint(outline, turned).signed_distance + outline.radius()) > tolerance) {
        symmetric = false;
        break;
      }
    }
    if (symmetric) return k;
  }
  return 1;
}

namespace {

// The contact samples of every finger's poses `fingers[k]` against `objects` (both already
// smoothed or not), each finger's gated on its own contact or force stream (with a contact sensor
// on any finger, one without contact rows never touched), finger by finger.
ContactPath PathOf(const push::Trajectory& traj, const std::vector<push::PoseSample>& objects,
                   const std::vector<std::vector<push::PoseSample>>& fingers, const RegistrationOptions& o) {
  bool any_contact_rows = !traj.measured.contact_point.empty();
  for (const push::ExtraFinger& e : traj.extra_fingers) any_contact_rows = any_contact_rows || !e.measured.contact_point.empty();
  auto nearest = [](const auto& stream, double t, int* index) {
    auto it = std::lower_bound(stream.begin(), stream.end(), t, [](const auto& a, double tt) { return a.t < tt; });
    double best = INFINITY;
    *index = -1;
    if (it != stream.end()) { best = it->t - t; *index = static_cast<int>(it - stream.begin()); }
    if (it != stream.begin() && t - (it - 1)->t < best) { best = t - (it - 1)->t; *index = static_cast<int>(it - stream.begin()) - 1; }
    return best;
  };
  ContactPath path;
  for (std::size_t finger = 0; finger < fingers.size(); ++finger) {
    const push::FingerStreams* extra = finger == 0 ? nullptr : &traj.extra_fingers[finger - 1].measured;
    const auto& contact = extra ? extra->contact_point : traj.measured.contact_point;
    const auto& force = extra ? extra->force : traj.measured.force;
    const FingerDisk disk = FingerAsDisk(finger == 0 ? traj.finger.shape : traj.extra_fingers[finger - 1].finger.shape);
    // A force stream that never shows a contact above its noise: the finger never touched (as the
    // graph takes it; its noise crossing the threshold had a passing finger's path fitted).
    std::size_t scanned = 0;
    if (contact.empty() && !any_contact_rows && !force.empty() &&
        !internal::ObjectSeenMoving(traj.measured.object_pose, o.pose_sigma_trans, &scanned) &&
        std::none_of(force.begin(), force.end(), [&](const push::ForceSample& s) {
          return internal::ForceContactHeld(force, s.t, o.contact_max_gap, o.contact_force_threshold, o.contact_force_sigma);
        }))
      continue;
    for (const push::PoseSample& f : fingers[finger]) {
      int k = -1;
      if (!contact.empty()) {
        if (nearest(contact, f.t, &k) > o.contact_max_gap) continue;
      } else if (any_contact_rows) {
        break;  // another finger has the contact sensor: this one never touched
      } else if (!force.empty()) {
        if (nearest(force, f.t, &k) > o.contact_max_gap || force[k].force.norm() < o.contact_force_threshold) continue;
      }
      // The object pose at f.t, interpolated across gaps of at most max_object_gap.
      auto it = std::lower_bound(objects.begin(), objects.end(), f.t - 1e-9, [](const auto& a, double tt) { return a.t < tt; });
      if (it == objects.end()) continue;
      Pose2 x;
      if (std::abs(it->t - f.t) <= 1e-9) {
        x = it->pose;
      } else {
        if (it == objects.begin() || it->t - (it - 1)->t > o.max_object_gap) continue;
        x = push::PoseAtClamped(it - 1, it + 1, f.t);
      }
      const Pose2 rel = geometry::Between(x, f.pose);
      path.t.push_back(f.t);
      path.relative.push_back(rel);
      path.q.push_back(geometry::Act(rel, disk.centre));
      path.finger.push_back(static_cast<int>(finger));
      path.radius.push_back(disk.radius);
    }
  }
  return path;
}

std::vector<push::PoseSample> WithNoise(std::vector<push::PoseSample> s, double trans, double rot,
                                                 std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  for (auto& p : s) p.pose = {p.pose.x + trans * n(rng), p.pose.y + trans * n(rng), p.pose.theta + rot * n(rng)};
  return s;
}

}  // namespace

ContactPath MeasuredContactPath(const push::Trajectory& traj, const RegistrationOptions& o) {
  const auto& m = traj.measured;
  // The raw noise: the recording's measurement sigmas, else the streams' own.
  double st = 0.0, sr = 0.0, ft = 0.0, unused = 0.0;
  if (traj.measurement_sigmas) {
    st = traj.measurement_sigmas->object_trans;
    sr = traj.measurement_sigmas->object_rot;
    ft = traj.measurement_sigmas->finger_trans;
  } else {
    StreamNoise(m.object_pose, &st, &sr);
    StreamNoise(m.finger_pose, &ft, &unused);
  }
  std::vector<std::vector<push::PoseSample>> raw_fingers{m.finger_pose};
  for (const push::ExtraFinger& e : traj.extra_fingers) raw_fingers.push_back(e.measured.finger_pose);
  if (!o.smooth) {
    ContactPath path = PathOf(traj, m.object_pose, raw_fingers, o);
    std::vector<double> radii;
    for (const Vec2& q : path.q) radii.push_back(q.norm());
    path.noise = std::sqrt(st * st + ft * ft + std::pow(sr * Median(radii), 2));
    return path;
  }
  // Noise-free streams still need a finite weight (ApplyMeasurementSigmas' floors).
  const double wt = std::max(st, 1e-4), wr = std::max(sr, 1e-3), wf = std::max(ft, 1e-4);
  const auto objects = Smoothed(m.object_pose, wt, wr, o.accel_trans, o.accel_rot);
  std::vector<std::vector<push::PoseSample>> fingers;
  for (const auto& poses : raw_fingers) fingers.push_back(Smoothed(poses, wf, 1.0, o.accel_trans, o.accel_rot));
  ContactPath path = PathOf(traj, objects, fingers, o);
  // The smoothed path's own noise, by a parametric bootstrap: the raw noise added to the
  // smoothed streams, smoothed again; the RMS change of q per axis. It depends on the rates
  // (a 25 Hz tracker is smoothed less than a 250 Hz one) and cannot be read off the residuals,
  // which a misplaced shape inflates.
  std::mt19937_64 rng(0x5eedULL + m.finger_pose.size());
  // The fingers' noise drawn first, the object's then (the order of the draws sets the bootstrap).
  std::vector<std::vector<push::PoseSample>> fingers_again;
  for (const auto& poses : fingers)
    fingers_again.push_back(Smoothed(WithNoise(poses, ft, 0.0, rng), wf, 1.0, o.accel_trans, o.accel_rot));
  const auto objects_again = Smoothed(WithNoise(objects, st, sr, rng), wt, wr, o.accel_trans, o.accel_rot);
  const ContactPath again = PathOf(traj, objects_again, fingers_again, o);
  double sum = 0.0;
  int count = 0;
  // Both paths hold the fingers' samples finger by finger, each finger's in time order.
  for (std::size_t i = 0, j = 0; i < path.t.size() && j < again.t.size();) {
    if (path.finger[i] != again.finger[j]) {
      (path.finger[i] < again.finger[j] ? i : j) += 1;
      continue;
    }
    if (path.t[i] < again.t[j]) { ++i; continue; }
    if (again.t[j] < path.t[i]) { ++j; continue; }
    sum += (again.q[j] - path.q[i]).squaredNorm();
    ++count, ++i, ++j;
  }
  path.noise = count > 0 ? std::sqrt(sum / (2.0 * count)) : 0.0;
  return path;
}

ShapeFitCheck CheckShapeFit(const push::Trajectory& trajectory, const RegistrationOptions& options) {
  return CheckShapeFit(std::vector<const push::Trajectory*>{&trajectory}, options);
}

ShapeFitCheck CheckShapeFit(const std::vector<const push::Trajectory*>& recordings, const RegistrationOptions& options) {
  if (recordings.empty()) throw GraphError("CheckShapeFit: no recording given");
  std::vector<double> spans;
  const Contacts c = PoolContacts(recordings, options, &spans);
  return CheckContacts(recordings.front()->object.shape, recordings.front()->finger.shape,
                       c.ForFit(options.max_refine_samples, spans, options), options);
}

RegistrationResult RegisterShape(const push::Trajectory& trajectory, const RegistrationOptions& options) {
  return RegisterShape(std::vector<const push::Trajectory*>{&trajectory}, options);
}

RegistrationResult RegisterShape(const std::vector<const push::Trajectory*>& recordings,
                                 const RegistrationOptions& o) {
  std::vector<double> spans;
  const Contacts all = PoolContacts(recordings, o, &spans);
  const Shape& file_shape = recordings.front()->object.shape;
  const Shape& finger = recordings.front()->finger.shape;
  const FingerDisk disk = FingerAsDisk(finger);
  const Contacts search = all.ForFit(o.max_search_samples, spans, o);
  const Contacts refine = all.ForFit(o.max_refine_samples, spans, o);
  RegistrationResult result;
  std::vector<double> radii;
  for (const Vec2& q : all.q) radii.push_back(q.norm());
  const double path_radius = Median(radii);
  // The smoothed path's noise is correlated over the correlation time; a fit of a few parameters
  // absorbs part of it, so the residuals' spread alone underestimates it: the bootstrap's floors it.
  const double min_noise = std::max(kMinPathNoise, all.noise);
  // The smoothed path's noise: given, else estimated from the best fit's residuals below.
  const double start_noise = o.noise > 0.0 ? o.noise : std::max(2e-3, all.noise);
  const Vec2 q_mid(Median([&] { std::vector<double> v; for (auto& q : search.q) v.push_back(q.x()); return v; }()),
                   Median([&] { std::vector<double> v; for (auto& q : search.q) v.push_back(q.y()); return v; }()));

  // Candidate files: units whose size matches the finger path, each as given and mirrored.
  std::vector<double> scales{1.0};
  // 100 and 1000: a file converted to metres twice (--scale 0.001 on a file already in metres
  // gave a rect2 footprint 1000 times too small; it "fit", being smaller than the fit tolerance).
  if (o.detect_units) scales.assign(std::begin(kUnitScales), std::end(kUnitScales));
  const Vec2 file_centroid = geometry::CoreCentroid(file_shape);
  const double file_radius = geometry::RadiusAbout(file_shape, file_centroid);
  std::vector<double> plausible;
  for (double s : scales) {
    const double ratio = s * file_radius / std::max(path_radius, 1e-6);
    if (ratio >= 0.25 && ratio <= 4.0) plausible.push_back(s);
  }
  // The path's radius is taken about the tracked origin, which lies near the middle of most
  // objects but may sit on an edge: a U-shaped block whose origin is on its outer edge, pushed
  // beside it, had its contacts 10 mm from the origin against a 60 mm radius (6 times), and its
  // true shape, in metres or millimetres, was refused as "no unit makes it fit". A unit within 30
  // times is plausible too where the shape in it, as given, lies on the contacts (the window
  // alone let a finger stream 0.4 m off in another frame reach the notched block made 100 times
  // larger: Alignment.AFingerStreamInAnotherFrameIsRefused).
  // The verdict on the shape as given (its gaps alone; the likelihood ratio comes below).
  const ShapeFitCheck as_given_check = CheckContacts(file_shape, finger, refine, o);
  for (double s : scales) {
    const double ratio = s * file_radius / std::max(path_radius, 1e-6);
    if (ratio <= 4.0 || ratio > 30.0 || std::find(plausible.begin(), plausible.end(), s) != plausible.end()) continue;
    const bool fits = s == 1.0 ? as_given_check.fits
                               : CheckContacts(geometry::TransformShape(file_shape, Pose2{}, s), finger, refine, o).fits;
    if (fits) plausible.push_back(s);
  }
  if (plausible.empty()) {
    plausible = scales;
    result.size_mismatch = true;
    result.size_ratio = file_radius / std::max(path_radius, 1e-9);
    result.notes.push_back(Format("no unit makes the shape (radius %.4g in file units) the size of the finger's path "
                                  "(%.4g m from the object origin): every unit tried",
                                  file_radius, path_radius));
  }

  struct FileCandidate {
    double scale = 1.0;
    bool mirrored = false;
    std::shared_ptr<Shape> shape;      // the file's shape scaled (and mirrored): placed by T only
    std::shared_ptr<const geometry::ShapePairQuerier> exact_finger;  // shared by its exact fits
    std::vector<Placement> placements;  // refined, best first
    int symmetry = 1;
    double radius = 0.0;
    double noise = 0.0;
  };
  auto by_cost = [](const Placement& a, const Placement& b) { return a.cost < b.cost; };
  std::vector<FileCandidate> files;
  for (double s : plausible) {
    for (bool mirror : {false, true}) {
      if (mirror && !o.detect_mirror) continue;
      FileCandidate f;
      f.scale = s;
      f.mirrored = mirror;
      try {
        f.shape = std::make_shared<Shape>(s == 1.0 && !mirror ? file_shape
                                                              : geometry::TransformShape(file_shape, Pose2{}, s, mirror));
      } catch (const geometry::GeometryError&) {
        continue;  // a unit that makes the shape smaller than the geometry supports (tried when none fits)
      }
      const Vec2 centroid = geometry::CoreCentroid(*f.shape);
      f.radius = geometry::RadiusAbout(*f.shape, centroid);
      f.symmetry = OutlineSymmetryOrder(*f.shape, centroid, std::max(2.5e-4, 3e-3 * f.radius));
      if (mirror && f.symmetry == 0) continue;  // a mirrored circle is the same circle
      const double prior_sigma = o.centroid_prior * f.radius;
      ContactFit coarse(*f.shape, search, finger, disk, start_noise, prior_sigma, o.gap_sigma);
      // Global search over theta (one turn of the symmetry); translation and gaps by robust GN
      // from the centroid-at-origin start and from a start that puts the nearest side under
      // the middle of the path.
      std::vector<Placement> grid;
      const double span = f.symmetry == 0 ? 0.0 : 2.0 * kPi / f.symmetry;
      const int count = f.symmetry == 0 ? 1 : std::max(1, static_cast<int>(std::ceil(span / o.rotation_step)));
      Active translation_only;
      translation_only.rotation = false;
      for (int k = 0; k < count; ++k) {
        const double theta = f.symmetry == 0 ? 0.0 : -0.5 * span + (k + 0.5) * span / count;
        Placement a = coarse.Start();
        a.x << -Rotate(centroid, theta), theta;
        Placement b = a;
        const geometry::PointQuery pq = geometry::QueryPoint(*f.shape, Pose2{a.x.x(), a.x.y(), theta}, q_mid);
        b.x.head<2>() += q_mid - disk.radius * pq.normal - pq.closest_point;
        coarse.Minimize(&a, translation_only, 12);
        coarse.Minimize(&b, translation_only, 12);
        grid.push_back(a.cost <= b.cost ? a : b);
      }
      // Local minima over the (cyclic) theta grid, best first, at most 4.
      std::vector<Placement> minima;
      const int n = static_cast<int>(grid.size());
      for (int k = 0; k < n; ++k) {
        if (n <= 2 || (grid[k].cost <= grid[(k + n - 1) % n].cost && grid[k].cost <= grid[(k + 1) % n].cost)) {
          minima.push_back(grid[k]);
        }
      }
      std::sort(minima.begin(), minima.end(), by_cost);
      if (minima.size() > 4) minima.resize(4);
      // And the best of each sector of the turn: one noisy push can rank the true placement
      // below others on contacts alone; the estimator's graph judges them all.
      const int sectors = f.symmetry == 0 ? 0 : std::max(1, o.sectors / std::max(1, f.symmetry));
      for (int k = 0; k < sectors && n > 0; ++k) {
        const int lo = k * n / sectors, hi = (k + 1) * n / sectors;
        if (hi <= lo) continue;
        const auto it = std::min_element(grid.begin() + lo, grid.begin() + hi, by_cost);
        it->sector = true;
        bool known = false;
        for (const Placement& m : minima) known = known || std::abs(m.x.z() - it->x.z()) < 1e-12;
        if (!known) minima.push_back(*it);
      }
      // Refinement with exact queries; the noise from the best fit's residuals unless given.
      ContactFit fine(*f.shape, refine, finger, disk, start_noise, prior_sigma, o.gap_sigma);
      f.exact_finger = fine.UseExactFinger();
      Active all_active;
      all_active.rotation = f.symmetry != 0;
      for (Placement& c : minima) fine.Minimize(&c, all_active, 30);
      std::sort(minima.begin(), minima.end(), by_cost);
      f.noise = start_noise;
      if (o.noise <= 0.0 && !minima.empty()) {
        std::vector<double> gaps;
        for (std::size_t i = 0; i < fine.size(); ++i) gaps.push_back(std::abs(fine.Gap(i, minima[0])));
        f.noise = std::max(min_noise, 1.4826 * WeightedMedian(gaps, refine.weight));
        fine.set_noise(f.noise);
        for (Placement& c : minima) fine.Minimize(&c, all_active, 30);
        std::sort(minima.begin(), minima.end(), by_cost);
      }
      f.placements = minima;
      if (!minima.empty()) files.push_back(std::move(f));
    }
  }
  if (files.empty()) throw GraphError("registration: no placement of the shape could be fitted");
  // The best file candidate at a common noise scale (each may have estimated its own); a
  // mirrored file must fit clearly better than the file as given (6 in log-likelihood).
  std::vector<double> costs;
  for (const FileCandidate& f : files) {
    ContactFit c(*f.shape, refine, finger, disk, files.front().noise, o.centroid_prior * f.radius, o.gap_sigma);
    c.UseExactFinger(f.exact_finger);
    costs.push_back(c.Cost(f.placements[0]) + (f.mirrored ? 6.0 : 0.0));
  }
  const std::size_t best_file = static_cast<std::size_t>(std::min_element(costs.begin(), costs.end()) - costs.begin());
  const FileCandidate& f = files[best_file];
  const double noise = f.noise;
  ContactFit fit(*f.shape, refine, finger, disk, noise, o.centroid_prior * f.radius, o.gap_sigma);
  fit.UseExactFinger(f.exact_finger);
  Placement best = f.placements[0];
  result.symmetry_order = f.symmetry;
  result.rotation_observable = f.symmetry != 0;
  result.noise = noise;
  result.samples = refine.SampleCount();
  for (double w : refine.weight) result.independent_samples += w;

  // Continuous scale (disk fingers), then the information at the solution.
  Active act;
  act.rotation = f.symmetry != 0;
  act.scale = o.estimate_scale && disk.exact;
  Eigen::MatrixXd info;
  fit.Minimize(&best, act, 30, &info);
  const Eigen::MatrixXd cov = info.inverse();
  {
    int k = 0;
    result.sigma.x() = std::sqrt(std::max(0.0, cov(k, k)));
    result.sigma.y() = std::sqrt(std::max(0.0, cov(k + 1, k + 1)));
    k = 2;
    if (act.rotation) result.sigma.z() = std::sqrt(std::max(0.0, cov(k, k))), ++k;
    if (act.scale) result.scale_sigma = std::sqrt(std::max(0.0, cov(k, k))) * f.scale * std::exp(best.log_scale);
  }
  result.transform.pose = {best.x.x(), best.x.y(), geometry::WrapAngle(best.x.z())};
  result.transform.scale = f.scale * std::exp(best.log_scale);
  result.transform.mirrored = f.mirrored;
  // Of the equivalent turns of a symmetric outline, report the one closest to 0.
  result.transform = CanonicalTransform(result.transform, file_shape, f.symmetry);
  result.aligned_cost = best.cost;
  result.gaps.assign(best.gap.data(), best.gap.data() + best.gap.size());

  // The shape as given, scored by the same fit, and the gap statistics.
  double gain_without_prior = 0.0;  // identity_cost - aligned_cost without the centroid prior's parts
  {
    ContactFit as_given(file_shape, refine, finger, disk, noise, o.centroid_prior * file_radius, o.gap_sigma);
    as_given.UseExactFinger(f.exact_finger);  // the same shape when the file won as given
    Placement identity = as_given.Start();
    as_given.Minimize(&identity, Active{false, false, false, true}, 20);  // its own calibration gaps
    result.identity_cost = identity.cost;
    gain_without_prior = (identity.cost - 0.5 * as_given.Prior(identity, nullptr).squaredNorm()) -
                         (best.cost - 0.5 * fit.Prior(best, nullptr).squaredNorm());
    std::vector<double> gaps;
    for (std::size_t i = 0; i < as_given.size(); ++i) gaps.push_back(std::abs(as_given.Gap(i, as_given.Start())));
    result.identity_gap_rms = 1.4826 * WeightedMedian(gaps, refine.weight);
    gaps.clear();
    for (std::size_t i = 0; i < fit.size(); ++i) gaps.push_back(std::abs(fit.Gap(i, best)));
    result.aligned_gap_rms = 1.4826 * WeightedMedian(gaps, refine.weight);
  }

  result.displacement = OutlineDisplacement(file_shape, result.transform);
  // The verdict rests on the shape as given alone, not on how much better the best fit is:
  // a better fit can come from samples that were never in contact (a finger sliding past the
  // end of a side makes the side look longer).
  result.check = as_given_check;
  // e.g. a quarter turn of a square; not a shape of no size for the data (one 1000 times too
  // small moves by less than the tolerance under any placement).
  const bool equivalent = result.displacement <= o.min_displacement && !result.size_mismatch;
  // Besides the gaps, the likelihood ratio: a placement that explains the contacts much better
  // (misfit_evidence in log-likelihood, the samples weighted by their correlation) and moves the
  // outline by more than the fit tolerance. On the 20 MIT recordings with their meshes as
  // shipped the ratio stays below 3; turns of 30 degrees gave 7 to 60 on single pushes, but a
  // push that breaks the model (a finger wedged between two walls) or loses a third of its
  // poses to occlusion reached 5 to 6 with the true shape: it is a suspicion, not a verdict.
  // The centroid prior (trackers that report the centroid) is no evidence against a file whose
  // origin lies on or outside its outline, a deliberate choice (a CAD part's corner), not a
  // centroid off by a shift: there the contacts' evidence alone counts. A user's plate with its
  // origin at a corner, 58 mm from the centroid, "fit better turned by 170 deg" by +22, of which
  // the prior was 20.5, on 12 of 12 simulated pushes of the true shape (CP warned; QS's graph
  // rejected the placement). Inside the outline the prior still counts: ellip1's mesh shifted by
  // (-2, 1.5) cm fits the contacts of some single pushes within their noise (one stretch of the
  // rim) and only the prior tells.
  const bool origin_on_outline =
      geometry::QueryPoint(file_shape, geometry::Vec2::Zero()).signed_distance >= -1e-3 * file_radius;
  result.evidence = origin_on_outline ? gain_without_prior : result.identity_cost - result.aligned_cost;
  result.better_elsewhere = !equivalent && result.evidence >= o.misfit_evidence && result.displacement > o.fit_tolerance;
  // With estimate_scale the continuous scale of a true shape comes back near, never at, 1 (0.9987
  // on a simulated push of the notched block): within three sigmas of 1, or moving the outline
  // by less than the fit tolerance, it is the file's own scale (as align_scale off would judge).
  const double scale_change = std::abs(result.transform.scale - 1.0);
  const bool unit_scale = result.transform.scale == 1.0 ||
                          (f.scale == 1.0 && act.scale &&
                           (scale_change <= 3.0 * result.scale_sigma || scale_change * file_radius <= o.fit_tolerance));
  result.fits_as_given = (result.check.fits || equivalent) && unit_scale && !f.mirrored;
  if (unit_scale && result.transform.scale != 1.0) {
    char text[200];
    std::snprintf(text, sizeof text,
                  "a scale of %.5g (sigma %.2g) fits the contacts slightly better; it moves the outline by less than the "
                  "fit tolerance or lies within three sigmas of 1, and is not applied",
                  result.transform.scale, result.scale_sigma);
    result.notes.push_back(text);
  }
  if (result.check.fits && (!unit_scale || f.mirrored)) {
    result.notes.push_back("the contacts lie on the shape as given, but they fit it better in other units or mirrored");
  }
  // Another explanation of a misfit: the shape as given with the finger larger or smaller (a
  // wrong probe radius or object size), each recording's gap free. Compared with the best
  // placement on the data and the centroid prior (gap priors left out of both).
  if (!result.fits_as_given) {
    ContactFit sized(file_shape, refine, finger, disk, noise, o.centroid_prior * file_radius, 1.0);
    sized.UseExactFinger(f.exact_finger);
    // From the shape as given, the gaps first, then a local refinement of the placement.
    Placement identity = sized.Start();
    sized.Minimize(&identity, Active{false, false, false, true}, 30);
    const double sized_cost = sized.Cost(identity, false);
    const double placed_cost = fit.Cost(best, false);
    result.size_offset = identity.gap.size() > 0 ? identity.gap.mean() : 0.0;
    // A finger more than 3 times its radius (at least 5 mm) off is a frame error, not a size one.
    const double plausible = std::max(5e-3, 3.0 * disk.radius);
    // The placement has two more parameters (x, y, theta against the size): a BIC-like margin
    // of log(independent samples) for them.
    // A wrong radius or size offsets every recording alike: recordings whose own gaps differ by
    // more than the fit tolerance (one side of a turned rectangle pushed in each) are a frame error.
    const double spread = identity.gap.size() > 0 ? (identity.gap.array() - result.size_offset).abs().maxCoeff() : 0.0;
    result.size_explains = sized_cost <= placed_cost + std::log(std::max(2.0, result.independent_samples)) &&
                           std::abs(result.size_offset) <= plausible && spread <= o.fit_tolerance &&
                           disk.radius + result.size_offset > 0.0 &&  // a finger, not a negative radius
                           std::abs(result.size_offset) >= 0.5 * o.gap_sigma;
    if (result.size_explains) {
      result.notes.push_back(Format("the shape as given fits as well with the finger %.1f mm %s (cost %.1f against %.1f for the "
                                    "best placement): a wrong probe radius or object size rather than a wrong frame",
                                    std::abs(result.size_offset) * 1e3, result.size_offset > 0 ? "larger" : "smaller",
                                    sized_cost, placed_cost));
    }
  }

  // Directions the contacts leave to the prior: the data's information (the priors removed)
  // below the centroid prior's 1 / sigma^2.
  {
    const double prior_sigma = o.centroid_prior * f.radius;
    Eigen::Matrix<double, 2, 4> Jp;
    fit.Prior(best, &Jp);
    const int np = 2 + (act.rotation ? 1 : 0) + (act.scale ? 1 : 0);
    Eigen::MatrixXd data = info;
    std::vector<int> idx{0, 1};
    if (act.rotation) idx.push_back(2);
    if (act.scale) idx.push_back(3);
    for (int a = 0; a < np; ++a) {
      for (int b = 0; b < np; ++b) data(a, b) -= Jp.col(idx[a]).dot(Jp.col(idx[b]));
    }
    for (int k = np; k < data.rows(); ++k) data(k, k) -= 1.0 / (o.gap_sigma * o.gap_sigma);
    // The translation's information with the rotation, scale and gaps eliminated.
    Eigen::Matrix2d translation = data.topLeftCorner<2, 2>();
    if (data.rows() > 2) {
      const Eigen::MatrixXd B = data.topRightCorner(2, data.cols() - 2);
      Eigen::MatrixXd C = data.bottomRightCorner(data.rows() - 2, data.cols() - 2);
      C.diagonal().array() += 1e-12 * (1.0 + C.diagonal().array().abs());
      translation -= B * C.ldlt().solve(B.transpose());
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(translation);
    for (int k = 0; k < 2; ++k) {
      if (eig.eigenvalues()(k) * prior_sigma * prior_sigma >= 1.0) continue;
      const Vec2 u = eig.eigenvectors().col(k);
      result.weak_directions.push_back(u);
      result.notes.push_back(Format("the contacts do not fix the position along (%.2f, %.2f): the centroid prior sets it "
                                    "(sigma %.1f mm)",
                                    u.x(), u.y(), prior_sigma * 1e3));
    }
  }

  // Symmetry, ambiguity and units notes.
  if (f.symmetry == 0) {
    result.notes.push_back("the outline is a circle about its centroid: the rotation is unobservable and kept at 0");
  } else if (f.symmetry > 1) {
    result.notes.push_back(Format("the outline is %d-fold symmetric: the rotation is determined modulo %.1f deg "
                                  "(the turn closest to 0 is reported)",
                                  f.symmetry, 360.0 / f.symmetry));
  }
  const Shape outline = OutlineOf(*f.shape);
  const std::vector<Vec2> samples = OutlineSamples(*f.shape);
  const double tolerance = std::max(2.5e-4, 3e-3 * f.radius);
  // The other local minima over the rotation: alternatives for a caller that can judge them
  // on more than contacts (the estimator runs its graph on each), and the ambiguity note.
  std::vector<Placement> kept{f.placements[0]};
  for (std::size_t k = 1; k < f.placements.size(); ++k) {
    const Placement& other = f.placements[k];
    if (!other.sector && other.cost - f.placements[0].cost > o.alternative_margin) continue;
    bool same = false;
    for (const Placement& p : kept) same = same || SamePlacement(outline, samples, p, other, tolerance);
    if (same) continue;
    kept.push_back(other);
    ShapeTransform alt;
    alt.pose = {other.x.x(), other.x.y(), geometry::WrapAngle(other.x.z())};
    alt.scale = f.scale * std::exp(other.log_scale);
    alt.mirrored = f.mirrored;
    result.alternatives.push_back(CanonicalTransform(alt, file_shape, f.symmetry));
    result.alternative_costs.push_back(other.cost - f.placements[0].cost);
    if (!result.ambiguous && other.cost - f.placements[0].cost < 3.0) {
      result.ambiguous = true;
      result.ambiguity = Format("turned by %.1f deg (shifted by (%.1f, %.1f) mm) fits the contacts almost as well "
                                "(cost %.2f against %.2f)",
                                geometry::WrapAngle(other.x.z()) * 180.0 / kPi, other.x.x() * 1e3, other.x.y() * 1e3,
                                other.cost, f.placements[0].cost);
    }
  }
  if (f.scale != 1.0) {
    result.notes.push_back("units: " + UnitPhrase(f.scale) +
                           Format(": at scale 1 it is %.3g times the size of the finger's path", file_radius / path_radius));
  }
  if (f.mirrored) result.notes.push_back("the shape file is mirrored (y -> -y): a footprint seen from below?");
  result.notes.push_back(Format("%d contact samples from %zu recording(s), noise %.2f mm", result.samples,
                                recordings.size(), noise * 1e3) +
                         Format("; contact gap RMS as given %.2f mm, aligned %.2f mm", result.identity_gap_rms * 1e3,
                                result.aligned_gap_rms * 1e3));
  return result;
}

}  // namespace pushgraph::graph
