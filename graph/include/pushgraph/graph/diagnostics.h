#pragma once
// Self-diagnosis of an estimate: does the data agree with the model it was estimated with?
// Every estimate carries (EstimationResult::diagnostics, RESULT.json "diagnostics"):
//
// - per factor type, the sum of squared whitened residuals (chi-square, robust losses not
//   applied) against its expected value at the optimum, E[chi2] = dof - sum of the leverages
//   tr(J_i Sigma_i J_i^T) (J_i the factor's whitened Jacobian, Sigma_i the joint marginal
//   covariance of its blocks; the leverages of all factors add up to the number of unknowns).
//   A ratio far above 1 says that factor's sigma or model is wrong for this data;
// - the signed finger-object separation during contact at the estimate, and the share of steps
//   where the finger is inside the object;
// - the measured contact gap: every measured finger pose during contact against the object at
//   its estimated pose. A consistent offset means a wrong probe radius or object size;
// - sensor faults: a stream that repeats its values (frozen) or has isolated residuals beyond
//   6 sigma (spikes);
// - the probable causes, one sentence each, when these are far off (also in the warnings).
//
//   graph::EstimationResult r = graph::Estimate(traj, graph::Model::kQs, graph::Mode::kBatch);
//   for (const auto& f : r.diagnostics->factors) std::cout << f.type << " " << f.Ratio() << "\n";
//   for (const std::string& cause : r.diagnostics->causes) std::cerr << cause << "\n";
#include <string>
#include <vector>

namespace pushgraph::graph {

struct FactorStatistics {
  std::string type;       ///< "object_pose", "finger_pose", "contact_point", "force", "contact_on_object", ...
  int count = 0;          ///< residual blocks
  int dof = 0;            ///< residual dimensions
  double chi2 = 0.0;      ///< sum of squared whitened residuals, no robust loss
  double expected = 0.0;  ///< E[chi2] at the optimum (dof minus leverages)
  double worst = 0.0;     ///< largest whitened residual norm of one block
  double worst_t = 0.0;   ///< time of the step it belongs to (its newest step)
  /// chi2 / expected: about 1 when the factor's sigma and model fit the data.
  double Ratio() const { return expected > 0.0 ? chi2 / expected : 0.0; }
};

struct SensorFault {
  std::string stream;  ///< "object_pose", "finger_pose", "contact_point", "force"
  std::string kind;    ///< "frozen" or "spikes"
  std::string detail;  ///< one sentence with the numbers
};

/// A finger's measured contact gap (m): median and median absolute deviation over its samples.
struct MeasuredContactGap {
  double median = 0.0, mad = 0.0;
  int samples = 0;
};

struct Diagnostics {
  std::vector<FactorStatistics> factors;
  /// Expected values from the marginal covariances (leverages); false: dof (m - n) / m, the
  /// share of the residual dimensions the n unknowns leave free.
  bool expected_from_covariance = false;
  int contact_steps = 0;
  /// Signed finger-object separation (m) at the estimate over the contact steps: median, RMS
  /// and the 95th percentile of its magnitude.
  double gap_median = 0.0, gap_rms = 0.0, gap_p95 = 0.0;
  /// Share of all steps whose finger is inside the object by more than penetration_tolerance.
  double penetration_share = 0.0;
  double penetration_tolerance = 1e-3;  ///< m: twice the default sigma of S
  /// The measured contact gap (m): median and median absolute deviation of the separation of
  /// each measured finger pose (in contact) from the object at its estimated pose, to first
  /// order about the estimated finger (along its contact normal: unbiased where the finger sits
  /// between two walls, where the nearer wall's distance is not).
  double measured_gap_median = 0.0, measured_gap_mad = 0.0;
  int measured_samples = 0;
  double measured_noise = 0.0;  ///< 1.4826 MAD: the per-sample noise of that separation
  /// The same of fingers 1, 2, ... of a push with several (each its own shape and pose samples);
  /// empty with one finger.
  std::vector<MeasuredContactGap> other_finger_gaps;
  std::vector<SensorFault> faults;
  /// Probable causes when something is far off, one sentence each (also in the warnings).
  std::vector<std::string> causes;
  /// The largest chi2 / expected over the measurement and contact factors with 20 or more
  /// degrees of freedom: a one-number health figure (about 1 is healthy; evaluate ranks by it).
  double score = 0.0;
  std::string worst_factor;  ///< the factor type of `score`
};

}  // namespace pushgraph::graph
