// Measurement noise models for simulated pushes (see noise.h).
#include <pushgraph/push/errors.h>
#include <pushgraph/push/noise.h>
#include <pushgraph/limit_surface/support.h>

#include <cmath>
#include <string>

namespace pushgraph::push {
using namespace limit_surface;
namespace {

// SplitMix64 (Steele, Lea, Flood 2014): decorrelated seeds for the per-stream generators.
std::uint64_t SplitMix(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

// Uniform in [0, 1) from the generator's raw output (53 bits): fixed across standard libraries,
// unlike std::uniform_real_distribution / std::normal_distribution.
double Uniform(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

void CheckScalar(const ScalarNoise& n, const std::string& where) {
  if (!std::isfinite(n.sigma) || n.sigma < 0.0)
    throw PushError("noise " + where + ".sigma must be finite and >= 0 (got " + std::to_string(n.sigma) + ")");
  if (!std::isfinite(n.offset_ratio) || n.offset_ratio < 0.0 || n.offset_ratio >= 1.0)
    throw PushError("noise " + where + ".offset_ratio must be in [0, 1) (got " + std::to_string(n.offset_ratio) +
                            ")");
}

void CheckStream(const StreamNoise& s, const std::string& name) {
  CheckScalar(s.position, name + ".position");
  CheckScalar(s.angle, name + ".angle");
  if (!std::isfinite(s.outlier_probability) || s.outlier_probability < 0.0 || s.outlier_probability > 1.0)
    throw PushError("noise " + name + ".outlier_probability must be in [0, 1] (got " +
                            std::to_string(s.outlier_probability) + ")");
  if (!std::isfinite(s.outlier_magnitude) || s.outlier_magnitude < 0.0)
    throw PushError("noise " + name + ".outlier_magnitude must be finite and >= 0");
  if (!std::isfinite(s.outlier_angle) || s.outlier_angle < 0.0)
    throw PushError("noise " + name + ".outlier_angle must be finite and >= 0");
}

void CheckWindow(double t0, double t1, const std::string& where) {
  if (!std::isfinite(t0) || !std::isfinite(t1) || t1 < t0)
    throw PushError(where + " must satisfy t0 <= t1, both finite (got " + std::to_string(t0) + ", " +
                            std::to_string(t1) + ")");
}

bool Inside(double t, double t0, double t1) { return t >= t0 && t <= t1; }

// One sample's additive noise: position (x, y), angle, then an outlier draw. The number of
// generator calls per sample is fixed, so the noise of sample k depends only on the seed and k.
struct Draw {
  geometry::Vec2 position{0.0, 0.0};
  double angle = 0.0;
};

Draw DrawNoise(const StreamNoise& s, double scale, std::mt19937_64& rng) {
  Draw d;
  const double nx = s.position.Sample(rng), ny = s.position.Sample(rng), na = s.angle.Sample(rng);
  d.position = scale * geometry::Vec2(nx, ny);
  d.angle = scale * na;
  const double u_outlier = Uniform(rng), u_direction = Uniform(rng), u_sign = Uniform(rng);
  if (u_outlier < s.outlier_probability) {
    const double a = 2.0 * M_PI * u_direction;
    d.position += s.outlier_magnitude * geometry::Vec2(std::cos(a), std::sin(a));
    d.angle += (u_sign < 0.5 ? -1.0 : 1.0) * s.outlier_angle;
  }
  return d;
}

}  // namespace

double ScalarNoise::Sample(std::mt19937_64& rng) const {
  // Always consume the same number of draws (3) whatever the kind: deterministic layout.
  const double a = Uniform(rng), b = Uniform(rng), c = Uniform(rng);
  switch (kind) {
    case NoiseKind::kNone: return 0.0;
    case NoiseKind::kGaussian: {
      const double u1 = a > 0.0 ? a : 0x1.0p-53;
      return sigma * std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * b);
    }
    case NoiseKind::kBimodal: {
      const double offset = offset_ratio * sigma;
      const double half_width = std::sqrt(6.0 * (1.0 - offset_ratio * offset_ratio)) * sigma;
      const double mode = c < 0.5 ? -offset : offset;
      return mode + half_width * (a + b - 1.0);  // triangular on [mode - w, mode + w]
    }
  }
  return 0.0;
}

NoiseModel DefaultNoise(NoiseKind kind) {
  NoiseModel m;
  auto set = [kind](StreamNoise& s, double sigma_position, double sigma_angle) {
    s.position = {kind, sigma_position};
    s.angle = {kind, sigma_angle};
  };
  set(m.object_pose, 0.002, 0.02);
  set(m.finger_pose, 0.0005, 0.0);
  set(m.contact_point, 0.001, 0.0);
  set(m.force, 0.05, 0.0);
  return m;
}

void ValidateNoise(const NoiseModel& model) {
  CheckStream(model.object_pose, "object_pose");
  CheckStream(model.finger_pose, "finger_pose");
  CheckStream(model.contact_point, "contact_point");
  CheckStream(model.force, "force");
  for (std::size_t i = 0; i < model.occlusions.size(); ++i) {
    const OcclusionWindow& w = model.occlusions[i];
    CheckWindow(w.t0, w.t1, "noise occlusions[" + std::to_string(i) + "]");
    if (!std::isfinite(w.sigma_scale) || w.sigma_scale < 0.0)
      throw PushError("noise occlusions[" + std::to_string(i) + "].sigma_scale must be finite and >= 0");
  }
  for (std::size_t i = 0; i < model.frozen_force.size(); ++i) {
    const FrozenWindow& w = model.frozen_force[i];
    CheckWindow(w.t0, w.t1, "noise frozen_force[" + std::to_string(i) + "]");
    if (w.value && !w.value->allFinite())
      throw PushError("noise frozen_force[" + std::to_string(i) + "].value must be finite");
  }
}

Streams ApplyNoise(const Streams& truth, const NoiseModel& model, std::uint64_t seed) {
  ValidateNoise(model);
  auto rng_for = [seed](std::uint64_t stream) { return std::mt19937_64(SplitMix(seed ^ SplitMix(stream + 1))); };
  Streams out;

  {  // object pose: noise, occlusion windows
    std::mt19937_64 rng = rng_for(0);
    for (const PoseSample& s : truth.object_pose) {
      const OcclusionWindow* occlusion = nullptr;
      for (const OcclusionWindow& w : model.occlusions)
        if (Inside(s.t, w.t0, w.t1)) occlusion = occlusion && occlusion->mode == OcclusionMode::kStop ? occlusion : &w;
      StreamNoise noise = model.object_pose;
      double scale = 1.0;
      if (occlusion && occlusion->mode == OcclusionMode::kDegrade) {
        scale = occlusion->sigma_scale;
        if (noise.position.kind == NoiseKind::kNone) noise.position = {NoiseKind::kGaussian, 0.001};
        if (noise.angle.kind == NoiseKind::kNone) noise.angle = {NoiseKind::kGaussian, 0.01};
      }
      const Draw d = DrawNoise(noise, scale, rng);  // drawn even when dropped: fixed layout
      if (occlusion && occlusion->mode == OcclusionMode::kStop) continue;
      PoseSample m = s;
      m.pose.x += d.position.x();
      m.pose.y += d.position.y();
      m.pose.theta += d.angle;
      out.object_pose.push_back(m);
    }
  }
  {  // finger pose
    std::mt19937_64 rng = rng_for(1);
    for (const PoseSample& s : truth.finger_pose) {
      const Draw d = DrawNoise(model.finger_pose, 1.0, rng);
      PoseSample m = s;
      m.pose.x += d.position.x();
      m.pose.y += d.position.y();
      m.pose.theta += d.angle;
      out.finger_pose.push_back(m);
    }
  }
  {  // contact point
    std::mt19937_64 rng = rng_for(2);
    for (const PointSample& s : truth.contact_point) {
      const Draw d = DrawNoise(model.contact_point, 1.0, rng);
      out.contact_point.push_back({s.t, s.point + d.position});
    }
  }
  {  // force, with frozen windows
    std::mt19937_64 rng = rng_for(3);
    std::vector<std::optional<geometry::Vec2>> stuck(model.frozen_force.size());
    for (const ForceSample& s : truth.force) {
      const Draw d = DrawNoise(model.force, 1.0, rng);
      ForceSample m{s.t, s.force + d.position};
      for (std::size_t i = 0; i < model.frozen_force.size(); ++i) {
        const FrozenWindow& w = model.frozen_force[i];
        if (!Inside(s.t, w.t0, w.t1)) continue;
        if (!stuck[i]) {
          if (w.value) stuck[i] = *w.value;
          else if (!out.force.empty()) stuck[i] = out.force.back().force;
          else stuck[i] = s.force;
        }
        m.force = *stuck[i];
        break;
      }
      out.force.push_back(m);
    }
  }
  return out;
}

MeasurementSigmas SigmasOf(const NoiseModel& model) {
  auto sigma = [](const ScalarNoise& n) { return n.kind == NoiseKind::kNone ? 0.0 : n.sigma; };
  MeasurementSigmas s;
  s.object_trans = sigma(model.object_pose.position);
  s.object_rot = sigma(model.object_pose.angle);
  s.finger_trans = sigma(model.finger_pose.position);
  s.finger_rot = sigma(model.finger_pose.angle);
  s.contact = sigma(model.contact_point.position);
  s.force = sigma(model.force.position);
  return s;
}

}  // namespace pushgraph::push
