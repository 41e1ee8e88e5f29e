// Self-diagnosis of an estimate (diagnostics.h): the graph rebuilt at the estimate, chi-square
// per factor type against its leverage-corrected expectation, contact gaps, sensor faults and
// the probable causes.
#include "graph_builder.h"
#include "text.h"

#include <pushgraph/geometry/point_query.h>
#include <pushgraph/graph/diagnostics.h>
#include <pushgraph/graph/marginals.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <optional>
#include <set>

namespace pushgraph::graph::internal {
namespace {

using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;




// A stream that repeats its values: a run of identical samples that no live sensor gives,
// at least max(20, 10% of the stream) long, or half of all samples repeating. `counts(i, j)`
// says whether a run over samples [i, j] is a fault (a force in contact, a pose while the
// estimate moves): a resting, noise-free stream repeats legitimately.
template <class Sample, class Value, class Counts>
void CheckFrozen(const std::vector<Sample>& stream, const char* name, Value value, Counts counts,
                 std::vector<SensorFault>* faults) {
  if (stream.size() < 20) return;
  int repeats = 0, longest = 0;
  double longest_t0 = 0.0, longest_t1 = 0.0;
  std::set<std::vector<double>> distinct;
  for (std::size_t i = 0, start = 0; i < stream.size(); ++i) {
    const std::vector<double> v = value(stream[i]);
    if (distinct.size() <= 64) distinct.insert(v);
    const bool same = i > 0 && v == value(stream[i - 1]);
    if (!same) start = i;
    if (same && counts(start, i)) {
      ++repeats;
      if (static_cast<int>(i - start) + 1 > longest) {
        longest = static_cast<int>(i - start) + 1;
        longest_t0 = stream[start].t;
        longest_t1 = stream[i].t;
      }
    }
  }
  const double share = static_cast<double>(repeats) / (stream.size() - 1);
  if (longest >= std::max<int>(20, static_cast<int>(stream.size() / 10)) || share >= 0.5) {
    faults->push_back({name, "frozen",
                       Format("the %s stream repeats one value for %d samples (t = %.3f to %.3f s; %.0f%% of its %zu "
                              "samples repeat the previous one, %zu%s distinct values): a frozen sensor",
                              name, longest, longest_t0, longest_t1, share * 100.0, stream.size(), distinct.size(),
                              distinct.size() > 64 ? "+" : "")});
  }
}

}  // namespace

Diagnostics Diagnose(const push::Trajectory& traj, Model model, const EstimatorConfig& cfg,
                     const EstimationResult& result, const FrameState* frame,
                     std::shared_ptr<const geometry::ShapePairQuerier> querier) {
  Diagnostics d;
  GraphBuilder builder(traj, model, cfg, std::move(querier));
  const int n = static_cast<int>(builder.steps().size());
  if (n != static_cast<int>(result.states.size())) {
    d.causes.push_back("diagnostics not computed: the estimate's steps do not match the trajectory's");
    return d;
  }
  if (frame) builder.EnableShapeFrame(frame->centroid, frame->sigma_centroid, frame->sigma_theta, frame->rotation);
  if (frame) builder.SetFrame(frame->frame);
  if (result.c_estimated) builder.EnableCEstimation();
  if (result.mu_estimated) builder.EnableMuEstimation();
  builder.SetSharedParameters(result.c, result.mu);
  for (int i = 0; i < n; ++i) builder.SetState(i, result.states[i]);
  std::vector<TaggedBlock> tags;
  builder.RecordFactorTypes(&tags);
  ceres::Problem::Options po;
  ceres::Problem problem(po);
  for (int i = 0; i < n; ++i) builder.AddFactors(problem, i);
  builder.RecordFactorTypes(nullptr);

  // The step each residual block belongs to: its newest variable block's step.
  std::map<const double*, int> step_of;
  for (int i = 0; i < n; ++i) {
    for (double* b : builder.Blocks(i)) step_of[b] = i;
  }
  // Leverages need the joint marginal covariance of each factor's blocks.
  SparseMarginals marginals;
  // Leverages need two or three digits, not the four kept for reported covariances: a 2061-step
  // ellip1 recording at its full rate (pivot ratio 3e-11) fell back to the rough dof (m - n) / m
  // and named a correct tracker's noise 3.1 times too large.
  marginals.set_accepted_pivot_ratio(1e-13);
  d.expected_from_covariance = cfg.covariance && marginals.Compute(problem);
  long residual_dims = 0;
  std::map<FactorType, FactorStatistics> stats;
  std::vector<std::pair<FactorType, double>> block_norms;
  for (const TaggedBlock& tag : tags) {
    const ceres::CostFunction* cost = problem.GetCostFunctionForResidualBlock(tag.id);
    const int m = cost->num_residuals();
    std::vector<double*> blocks;
    problem.GetParameterBlocksForResidualBlock(tag.id, &blocks);
    std::vector<double> r(m);
    std::vector<RowMatrix> J(blocks.size());
    std::vector<double*> jac(blocks.size());
    for (std::size_t k = 0; k < blocks.size(); ++k) {
      J[k].resize(m, cost->parameter_block_sizes()[k]);
      jac[k] = J[k].data();
    }
    double c = 0.0;
    if (!problem.EvaluateResidualBlock(tag.id, false, &c, r.data(), d.expected_from_covariance ? jac.data() : nullptr)) continue;
    FactorStatistics& f = stats[tag.type];
    f.type = FactorTypeName(tag.type);
    ++f.count;
    f.dof += m;
    residual_dims += m;
    const double norm2 = Eigen::Map<const Eigen::VectorXd>(r.data(), m).squaredNorm();
    f.chi2 += norm2;
    int step = 0;
    for (double* b : blocks) {
      auto it = step_of.find(b);
      if (it != step_of.end()) step = std::max(step, it->second);
    }
    if (std::sqrt(norm2) > f.worst) {
      f.worst = std::sqrt(norm2);
      f.worst_t = builder.steps()[step].t;
    }
    block_norms.emplace_back(tag.type, std::sqrt(norm2));
    if (d.expected_from_covariance) {
      // Leverage tr(J Sigma J^T) over the blocks' joint covariance; pairs the factorization does
      // not hold cannot occur (the blocks share this factor).
      double lev = 0.0;
      for (std::size_t a = 0; a < blocks.size(); ++a) {
        for (std::size_t b = 0; b < blocks.size(); ++b) {
          if (problem.IsParameterBlockConstant(blocks[a]) || problem.IsParameterBlockConstant(blocks[b])) continue;
          const Eigen::MatrixXd S = a == b ? marginals.Covariance(blocks[a]) : marginals.CrossCovariance(blocks[a], blocks[b]);
          lev += (J[a] * S * J[b].transpose()).trace();
        }
      }
      f.expected += lev;  // subtracted from dof below
    }
  }
  const double unknowns = [&] {
    double total = 0.0;
    std::vector<double*> all;
    problem.GetParameterBlocks(&all);
    for (double* b : all) total += problem.IsParameterBlockConstant(b) ? 0 : problem.ParameterBlockSize(b);
    return total;
  }();
  for (auto& [type, f] : stats) {
    f.expected = d.expected_from_covariance ? f.dof - f.expected
                                            : f.dof * std::max(0.0, 1.0 - unknowns / std::max<long>(1, residual_dims));
    f.expected = std::max(f.expected, 1e-3 * f.dof);
    d.factors.push_back(f);
  }

  // Contact gaps at the estimate, and penetration over all steps.
  std::vector<double> gaps;
  int penetrating = 0;
  const Pose2 F = frame ? frame->frame : Pose2{};
  for (int i = 0; i < n; ++i) {
    const StateEstimate& s = result.states[i];
    const double sd = builder.querier().Query(geometry::Compose(s.object_pose, F), s.finger_pose).signed_distance;
    penetrating += sd < -d.penetration_tolerance ? 1 : 0;
    if (builder.steps()[i].in_contact) gaps.push_back(sd);
  }
  d.penetration_share = n > 0 ? static_cast<double>(penetrating) / n : 0.0;
  d.contact_steps = static_cast<int>(gaps.size());
  if (!gaps.empty()) {
    d.gap_median = Median(gaps);
    double sum = 0.0;
    std::vector<double> mags;
    for (double g : gaps) { sum += g * g; mags.push_back(std::abs(g)); }
    d.gap_rms = std::sqrt(sum / gaps.size());
    std::sort(mags.begin(), mags.end());
    d.gap_p95 = mags[static_cast<std::size_t>(0.95 * (mags.size() - 1))];
  }
  // The measured gap: each measured finger pose during contact against the object at its
  // estimated pose, to first order about the estimated finger: sd(estimate) + dsd/de (measured -
  // estimated). The estimate's object (smoothed by the whole graph) carries no smoothing bias,
  // the finger samples' noise is independent, and its projection on one contact normal is zero
  // mean, so the median is precise to about 1.25 MAD / sqrt(n); the touching factor moves
  // mostly the estimated finger, not the object. (The signed distance of the sample itself is
  // the nearer wall's where the finger sits between two, as wedged in a notch: biased inward by
  // about half the noise, 1.1 mm at 2 mm and 3.0 mm at 5 mm on the notched block's V, which
  // named a correct probe radius wrong.)
  // Each finger's (fingers 1, 2, ... of a push with several, with their own shapes and pose samples).
  auto measured_gap = [&](int finger, MeasuredContactGap* out) {
    if (finger >= builder.num_fingers()) return;
    const geometry::ShapePairQuerier* querier = &builder.finger_querier(finger);
    const auto& poses = builder.FingerPoseRows(finger);
    std::vector<double> mg;
    for (int i = 0; i < n; ++i) {
      const Step& step = builder.steps()[i];
      const bool touching = builder.FingerTouches(i, finger);
      const int sample = finger == 0 ? step.finger : step.others[finger - 1].finger;
      if (!touching || sample < 0) continue;
      if (finger >= 1 && static_cast<int>(result.states[i].other_fingers.size()) < finger) continue;
      const Pose2 placed = geometry::Compose(result.states[i].object_pose, F);
      const Pose2& estimated = finger == 0 ? result.states[i].finger_pose : result.states[i].other_fingers[finger - 1].pose;
      geometry::ShapePairJacobians J;
      const double sd = querier->Query(placed, estimated, &J).signed_distance;
      Eigen::Vector3d delta = poses[sample].pose.vector() - estimated.vector();
      delta.z() = geometry::WrapAngle(delta.z());
      mg.push_back(sd + J.J_sd_finger_pose.dot(delta));
    }
    out->samples = static_cast<int>(mg.size());
    if (mg.empty()) return;
    out->median = Median(mg);
    std::vector<double> dev;
    for (double g : mg) dev.push_back(std::abs(g - out->median));
    out->mad = Median(dev);
  };
  {
    MeasuredContactGap gap;
    measured_gap(0, &gap);
    d.measured_samples = gap.samples;
    d.measured_gap_median = gap.median;
    d.measured_gap_mad = gap.mad;
    d.measured_noise = 1.4826 * gap.mad;
    for (std::size_t k = 1; k <= traj.extra_fingers.size(); ++k) {
      d.other_finger_gaps.emplace_back();
      measured_gap(static_cast<int>(k), &d.other_finger_gaps.back());
    }
  }

  // Sensor faults: frozen streams, and spikes (isolated residuals beyond 6 sigma).
  const auto& m = traj.measured;
  auto pose_value = [](const push::PoseSample& s) { return std::vector<double>{s.pose.x, s.pose.y, s.pose.theta}; };
  // A pose run is a fault when the estimate moves more than 1 mm or 0.01 rad meanwhile.
  auto moving = [&](double t0, double t1, bool object) {
    const auto lo = std::lower_bound(result.states.begin(), result.states.end(), t0, [](const StateEstimate& s, double t) { return s.t < t; });
    const auto hi = std::lower_bound(result.states.begin(), result.states.end(), t1, [](const StateEstimate& s, double t) { return s.t < t; });
    if (lo == result.states.end() || hi == result.states.end()) return false;
    const Pose2 a = object ? lo->object_pose : lo->finger_pose, b = object ? hi->object_pose : hi->finger_pose;
    return (a.translation() - b.translation()).norm() > 1e-3 || std::abs(a.theta - b.theta) > 0.01;
  };
  CheckFrozen(m.object_pose, "object_pose", pose_value,
              [&](std::size_t i, std::size_t j) { return moving(m.object_pose[i].t, m.object_pose[j].t, true); }, &d.faults);
  CheckFrozen(m.finger_pose, "finger_pose", pose_value,
              [&](std::size_t i, std::size_t j) { return moving(m.finger_pose[i].t, m.finger_pose[j].t, false); }, &d.faults);
  CheckFrozen(m.contact_point, "contact_point",
              [](const push::PointSample& s) { return std::vector<double>{s.point.x(), s.point.y()}; },
              [](std::size_t, std::size_t) { return true; }, &d.faults);
  CheckFrozen(m.force, "force", [](const push::ForceSample& s) { return std::vector<double>{s.force.x(), s.force.y()}; },
              [&](std::size_t i, std::size_t) { return m.force[i].force.norm() >= cfg.contact_force_threshold; }, &d.faults);
  // A force spike is also large against the force itself: over a tenth of the stream's 95th
  // percentile. A 50 kg push's contact onset (0 to 147 N within a 4 ms step, sigma 0.05 N) left
  // the estimate 3.4 N (68 sigma, 2 %) off two samples, and was called a spiking sensor.
  double force_spike_sigmas = 6.0;
  if (!m.force.empty() && cfg.measurement.force > 0.0) {
    std::vector<double> magnitudes;
    for (const push::ForceSample& f : m.force) magnitudes.push_back(f.force.norm());
    force_spike_sigmas = std::max(6.0, 0.1 * Percentile95(magnitudes) / cfg.measurement.force);
  }
  for (FactorType t : {FactorType::kObjectPose, FactorType::kFingerPose, FactorType::kContactPoint, FactorType::kForce}) {
    int count = 0, spikes = 0;
    double worst = 0.0;
    const double beyond = t == FactorType::kForce ? force_spike_sigmas : 6.0;
    for (const auto& [type, norm] : block_norms) {
      if (type != t) continue;
      ++count;
      if (norm > beyond) { ++spikes; worst = std::max(worst, norm); }
    }
    // Isolated: at most 2% of the samples; and not one unlucky 6-sigma draw: two or more of
    // them, or one beyond 10 sigma.
    if (spikes > 0 && spikes <= std::max(1, count / 50) && (spikes >= 2 || worst > 10.0)) {
      double at = 0.0;
      for (const FactorStatistics& f : d.factors) if (f.type == FactorTypeName(t)) at = f.worst_t;
      d.faults.push_back({FactorTypeName(t), "spikes",
                          Format("the %s stream has %d of %d samples more than %.0f sigma from the estimate (worst %.1f "
                                 "sigma at t = %.3f s): spikes",
                                 FactorTypeName(t), spikes, count, beyond, worst, at)});
    }
  }

  // The health figure and the probable causes.
  // The measurement factors are noise models; touching, S and D have physical meanings with
  // sigmas of the model's tolerance. C's sigma is a stiffness (the contact point is a
  // variable of the model itself): it is reported, not judged.
  // limit_surface_load too: without a force stream it is the only factor on the force's size,
  // and a mass 12 times too large (or in grams) drove rect1's forces to 0.14 N at a load ratio
  // of 19.8 with no word (it is about 0 at the right mass).
  static const std::set<std::string> kJudged = {"object_pose", "finger_pose", "contact_point", "force",
                                                "touching",    "intersection", "quasi_static", "limit_surface_load"};
  for (const FactorStatistics& f : d.factors) {
    if (kJudged.count(f.type) && f.dof >= 20 && f.Ratio() > d.score) {
      d.score = f.Ratio();
      d.worst_factor = f.type;
    }
  }
  for (const SensorFault& fault : d.faults) {
    d.causes.push_back(fault.kind == "frozen" ? "frozen sensor: " + fault.detail : "spiking sensor: " + fault.detail);
  }
  // With a misfit the shape check left in place (align_shape "off", or no placement won and no
  // finger size used) the gap is the shape file's frame or units as much as the probe's: a mesh
  // in millimetres estimated as given was told "a finger radius 5748.5 mm smaller would touch".
  const std::optional<ShapeAlignment>& shape = result.shape_alignment;
  const bool misfit_left = shape && shape->checked && !shape->check.fits && !shape->aligned && !shape->finger_radius;
  const char* misfit_note = " (or the shape file's frame or units: the shape check above found the shape as given off)";
  // Beyond 1 mm and three standard errors of the median (1.25 sigma / sqrt(n)).
  auto wrong_size = [&](int finger, double median, double mad, int samples) {
    const double median_error = 1.25 * 1.4826 * mad / std::sqrt(std::max(1, samples));
    if (samples < 20 || std::abs(median) <= std::max(1e-3, 3.0 * median_error)) return;
    const std::string who = finger == 0 ? "finger" : "finger " + std::to_string(finger);
    const std::string whose = finger == 0 ? "a finger" : who + "'s";
    d.causes.push_back(Format("wrong probe radius or object size: during contact the measured %s stays %.1f mm %s the "
                              "object's surface (median over %d samples); %s radius %.1f mm %s would touch%s",
                              who.c_str(), std::abs(median) * 1e3, median > 0 ? "off" : "inside", samples, whose.c_str(),
                              std::abs(median) * 1e3, median > 0 ? "larger" : "smaller", misfit_left ? misfit_note : ""));
  };
  wrong_size(0, d.measured_gap_median, d.measured_gap_mad, d.measured_samples);
  for (std::size_t k = 0; k < d.other_finger_gaps.size(); ++k) {
    const MeasuredContactGap& g = d.other_finger_gaps[k];
    wrong_size(static_cast<int>(k) + 1, g.median, g.mad, g.samples);
  }
  if (d.penetration_share > 0.2) {
    d.causes.push_back(Format("the finger is inside the object in %.0f%% of the steps (by more than %.1f mm): shape frame, "
                              "units, probe radius, or a finger touching two walls at once (several contacts)?",
                              d.penetration_share * 100.0, d.penetration_tolerance * 1e3));
  }
  for (const FactorStatistics& f : d.factors) {
    if (!kJudged.count(f.type) || f.dof < 20 || f.Ratio() <= 3.0) continue;
    std::string why;
    if (f.type == "object_pose" || f.type == "finger_pose") why = "the tracker's noise is larger than its sigma, or it jumps";
    else if (f.type == "force") why = "the force sensor's noise is larger than its sigma, or it is frozen or spiking";
    else if (f.type == "contact_point") why = "the contact sensor's noise is larger than its sigma";
    else if (f.type == "quasi_static")
      why = "the pushing model does not hold (c, friction, several contacts) or the shape's centre of pressure is off";
    else if (f.type == "limit_surface_load")
      why = "the sliding object's load is not mu_surface m g: check the mass (kg) and mu_surface, or the pushing "
            "model does not hold";
    else if (f.type == "touching" || f.type == "intersection")
      why = "the finger cannot touch the object where the data put it: shape frame, units, probe radius, or several "
            "contacts at once";
    else continue;
    // Concentrated in a few samples (at most 2 %), without which the rest fits: those samples, not
    // the sensor's noise (a 50 kg push's contact onset, 0 to 147 N within a 4 ms step, put 98 % of
    // the force chi-square in two samples the estimate follows to 2 %).
    std::vector<double> squares;
    for (const auto& [type, norm] : block_norms)
      if (FactorTypeName(type) == f.type) squares.push_back(norm * norm);
    std::sort(squares.begin(), squares.end(), std::greater<double>());
    const std::size_t few = std::max<std::size_t>(1, squares.size() / 50);
    double top = 0.0;
    for (std::size_t i = 0; i < few && i < squares.size(); ++i) top += squares[i];
    if (squares.size() >= 20 && top >= 0.8 * f.chi2 && (f.chi2 - top) <= 3.0 * f.expected) {
      d.causes.push_back(Format("%s residuals are %.1f times their expected size (chi-square %.0f for %.0f expected), "
                                "%.0f%% of it in the %zu largest of %zu samples (the worst at t = %.3f s), the rest as "
                                "expected: samples the estimate does not follow (a sudden change the model smooths, "
                                "such as a contact onset, or spikes)",
                                f.type.c_str(), f.Ratio(), f.chi2, f.expected, 100.0 * top / f.chi2, few,
                                squares.size(), f.worst_t));
      continue;
    }
    d.causes.push_back(Format("%s residuals are %.1f times their expected size (chi-square %.0f for %.0f expected): %s",
                              f.type.c_str(), f.Ratio(), f.chi2, f.expected, why.c_str()));
  }
  return d;
}

}  // namespace pushgraph::graph::internal
