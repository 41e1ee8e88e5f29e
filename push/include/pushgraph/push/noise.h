#pragma once
// Measurement noise for simulated pushes: Gaussian, the bimodal mixture of two triangular
// distributions of Lambert et al. (Sec. V-B, Table II), occlusion windows on the object stream
// (the paper's 85% occlusion in mid-trajectory: degraded or lost tracking), outliers, and a
// frozen force sensor (the fault of the real MIT rect1 recordings). Seeded and deterministic:
// the same seed and inputs give bit-identical output; each stream draws from its own
// std::mt19937_64, so adding samples to one stream never changes another's noise.
//
//   push::NoiseModel noise = push::DefaultNoise(push::NoiseKind::kBimodal);
//   noise.occlusions.push_back({0.8, 1.2, push::OcclusionMode::kStop});
//   noise.frozen_force.push_back({1.0, 1.5});
//   push::Streams measured = push::ApplyNoise(ground_truth, noise, /*seed=*/7);
#include <pushgraph/push/errors.h>
#include <pushgraph/push/trajectory.h>

#include <cstdint>
#include <optional>
#include <random>
#include <vector>

namespace pushgraph::push {

enum class NoiseKind {
  kNone,
  kGaussian,  ///< N(0, sigma^2)
  /// Equal-weight mixture of two symmetric triangular densities centred at +-a with half-width w,
  /// a = offset_ratio * sigma, w = sqrt(6 (1 - offset_ratio^2)) * sigma, so that the mixture has
  /// mean 0 and standard deviation sigma (variance a^2 + w^2 / 6). With the default offset_ratio
  /// 0.9 the density has two clear peaks at +-0.9 sigma and a dip at 0.
  kBimodal,
};

/// Noise of one scalar coordinate.
struct ScalarNoise {
  NoiseKind kind = NoiseKind::kNone;
  double sigma = 0.0;         ///< standard deviation (m, rad or N), >= 0
  double offset_ratio = 0.9;  ///< kBimodal: mode offset / sigma, in [0, 1)

  double Sample(std::mt19937_64& rng) const;
};

/// Noise of one stream. Positions/forces get independent x and y noise; poses also an angle.
struct StreamNoise {
  ScalarNoise position;             ///< x and y (m for poses/points, N for the force)
  ScalarNoise angle;                ///< poses only (rad)
  double outlier_probability = 0.0; ///< per sample, in [0, 1]
  double outlier_magnitude = 0.0;   ///< an outlier adds exactly this (m or N) in a uniform random direction
  double outlier_angle = 0.0;       ///< poses: an outlier also adds +-this (rad)
};

enum class OcclusionMode {
  kStop,     ///< no object samples inside the window (tracking lost)
  kDegrade,  ///< object samples kept, their noise multiplied by sigma_scale
};

/// A window [t0, t1] (s) during which the object stream is occluded.
struct OcclusionWindow {
  double t0 = 0.0;
  double t1 = 0.0;
  OcclusionMode mode = OcclusionMode::kStop;
  double sigma_scale = 10.0;  ///< kDegrade; with kNone noise a Gaussian of sigma_scale * 1 mm / 0.01 rad is used
};

/// A window [t0, t1] (s) during which the force sensor is stuck: every force sample in it reads
/// `value`, or, when unset, the last measured reading before t0 (the ground truth at t0 when
/// there is none). No noise is added to frozen samples.
struct FrozenWindow {
  double t0 = 0.0;
  double t1 = 0.0;
  std::optional<geometry::Vec2> value;
};

struct NoiseModel {
  StreamNoise object_pose;
  StreamNoise finger_pose;
  StreamNoise contact_point;
  StreamNoise force;
  std::vector<OcclusionWindow> occlusions;  ///< object stream only
  std::vector<FrozenWindow> frozen_force;   ///< force stream only
};

/// Per-stream defaults: object pose 2 mm / 0.02 rad (vision tracker), finger pose 0.5 mm / 0 rad
/// (joint encoders; the finger's angle is not measured meaningfully), contact point 1 mm,
/// force 0.05 N. kNone gives a model that leaves the streams unchanged.
NoiseModel DefaultNoise(NoiseKind kind);

/// Validates the model (throws LimitSurfaceError naming the field: negative sigma, probability
/// outside [0, 1], window with t1 < t0, NaN, ...).
void ValidateNoise(const NoiseModel& model);

/// The measured streams: ground truth plus noise, occlusion, outliers and frozen force.
Streams ApplyNoise(const Streams& truth, const NoiseModel& model, std::uint64_t seed);

/// The per-axis standard deviations of a noise model (outliers and occlusion windows aside).
MeasurementSigmas SigmasOf(const NoiseModel& model);

}  // namespace pushgraph::push
