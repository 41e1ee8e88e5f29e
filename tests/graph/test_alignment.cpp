// The estimator against shapes whose frame is not the recording's (EstimatorConfig::align_shape)
// and its self-diagnosis: simulated pushes of the notched block (exact ground truth) with the
// shape file turned, shifted and in millimetres; a wrong probe radius; a frozen force sensor.
#include <pushgraph/geometry/point_query.h>
#include <pushgraph/graph/estimator.h>
#include <pushgraph/push/scoring.h>
#include <pushgraph/push/simulator.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <string>

namespace pushgraph::graph {
namespace {

using geometry::Pose2;
using geometry::Shape;
using geometry::Vec2;

const std::string kData = std::string(PUSHGRAPH_SOURCE_DIR) + "/data/shapes/";

// A push of the notched block with the paper's Gaussian noise (5 mm, 0.05 rad, 0.5 N) on every
// stream, the sigmas recorded in the trajectory.
push::Trajectory NotchedPush(double angle, double offset, unsigned seed, const Shape& finger = Shape::Disk(0.005)) {
  push::PushPlan plan;
  plan.object.shape = geometry::LoadShapeJson(kData + "notched_block.json");
  plan.finger.shape = finger;
  plan.object.mass = 0.5;
  plan.object.mu_surface = 0.3;
  plan.finger.mu_contact = 0.4;
  plan.waypoints = push::StraightPushPath(plan, angle, offset, 0.005, 0.06);
  plan.noise = push::DefaultNoise(push::NoiseKind::kGaussian);
  for (push::StreamNoise* s : {&plan.noise.object_pose, &plan.noise.finger_pose, &plan.noise.contact_point}) {
    s->position.sigma = 0.005;
  }
  plan.noise.object_pose.angle.sigma = 0.05;
  plan.noise.force.position.sigma = 0.5;
  plan.seed = seed;
  return push::Simulate(plan).trajectory;
}

// `pushgraph simulate`'s default push of the notched block (along +y, 1 cm left of its centroid,
// the simulator's default noise) with the given standoff and travel.
push::PushPlan DefaultNoisePlan(double standoff, double distance) {
  push::PushPlan plan;
  plan.object.shape = geometry::LoadShapeJson(kData + "notched_block.json");
  plan.finger.shape = Shape::Disk(0.005);
  plan.object.mass = 0.5;
  plan.object.mu_surface = 0.3;
  plan.finger.mu_contact = 0.4;
  plan.waypoints = push::StraightPushPath(plan, M_PI / 2, 0.01, standoff, distance);
  plan.noise = push::DefaultNoise(push::NoiseKind::kGaussian);
  return plan;
}

// `pushgraph simulate`'s default push and noise, of another object.
push::Trajectory DefaultPushOf(const Shape& object, unsigned seed) {
  push::PushPlan plan = DefaultNoisePlan(0.005, 0.05);
  plan.object.shape = object;
  plan.waypoints = push::StraightPushPath(plan, M_PI / 2, 0.01, 0.005, 0.05);
  plan.seed = seed;
  return push::Simulate(plan).trajectory;
}

double OutlineDistance(const Shape& a, const Shape& b) {
  double worst = 0.0;
  for (const Shape* from : {&a, &b}) {
    const Shape& to = from == &a ? b : a;
    for (const auto& p : from->polygons()) {
      for (const Vec2& v : p.outer) worst = std::max(worst, std::abs(geometry::QueryPoint(to, v).signed_distance));
    }
  }
  return worst;
}

bool HasWarning(const EstimationResult& r, const std::string& text) {
  for (const std::string& w : r.warnings) {
    if (w.find(text) != std::string::npos) return true;
  }
  return false;
}

struct Misframe {
  const char* name;
  Pose2 pose;    // the file's frame: the true shape moved by this
  double scale;  // and its coordinates divided by this
};

// The shape file of the misframe, and the transform that undoes it.
Shape FileShape(const Shape& truth, const Misframe& m) {
  return geometry::TransformShape(geometry::TransformShape(truth, m.pose), Pose2{}, 1.0 / m.scale);
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// Three pushes in different directions, four misframes each. The shape as given is never
// "aligned" when it is the true one. A misframed one is flagged with alignment off (a misfit,
// or a better placement suspected) in all but one case and aligned by auto in all but three
// (a 30-degree turn that the noise hides within the gap tolerance is only suspected); how close
// the transform and the estimate come is printed and bounded on the median: one straight push
// with the paper's noise on a 25 Hz tracker can leave a turn about the contact, or the block's
// near-symmetric flip, undecided by both the contacts and the whole graph (docs/estimation.md,
// Shape registration). The MIT recordings, registered together, do far better (test_registration).
TEST(Alignment, MisframedShapesAreAlignedAndEstimatedAsWellAsTheTrueOne) {
  const Misframe misframes[] = {{"quarter turn", {0, 0, M_PI / 2}, 1.0},
                                {"30 deg", {0, 0, M_PI / 6}, 1.0},
                                {"2 cm, -1.5 cm", {0.02, -0.015, 0}, 1.0},
                                {"mm, -60 deg, 1 cm", {0.01, 0.004, -M_PI / 3}, 0.001}};
  std::vector<double> outlines, ratios, off_ratios;
  int cases = 0, flagged = 0, aligned_count = 0, ambiguous_count = 0, weak_count = 0, settled_count = 0;
  std::vector<double> settled_outlines;
  for (unsigned seed = 2; seed <= 4; ++seed) {
    const push::Trajectory truth = NotchedPush(1.1 * seed, 0.006 * ((seed % 3) - 1.0), seed);
    EstimatorConfig cfg = ApplyMeasurementSigmas({}, *truth.measurement_sigmas);
    const EstimationResult reference = Estimate(truth, Model::kQs, Mode::kBatch, cfg);
    ASSERT_TRUE(reference.shape_alignment && reference.shape_alignment->checked);
    EXPECT_TRUE(reference.shape_alignment->check.fits) << reference.shape_alignment->check.Describe();
    EXPECT_FALSE(reference.shape_alignment->aligned);
    if (getenv("ALIGN_VERBOSE")) {
      for (const std::string& n : reference.shape_alignment->notes) std::printf("   reference note: %s\n", n.c_str());
    }
    const double rms = reference.metrics.at("object_position_rms");
    for (const Misframe& m : misframes) {
      push::Trajectory t = truth;
      t.object.shape = FileShape(truth.object.shape, m);
      const EstimationResult aligned = Estimate(t, Model::kQs, Mode::kBatch, cfg);
      EstimatorConfig off = cfg;
      off.align_shape = EstimatorConfig::AlignShape::kOff;
      off.covariance = false;
      off.diagnostics = false;
      const EstimationResult raw = Estimate(t, Model::kQs, Mode::kBatch, off);
      if (getenv("ALIGN_VERBOSE")) {
        for (const std::string& w : aligned.warnings) std::printf("   warning: %s\n", w.c_str());
        if (aligned.shape_alignment) for (const std::string& n : aligned.shape_alignment->notes) std::printf("   note: %s\n", n.c_str());
      }
      ++cases;
      EXPECT_FALSE(raw.shape_alignment->aligned);
      // Flagged: the warning says what to do (align, or, where other placements fit about as well,
      // that this recording does not settle the placement).
      const bool is_flagged = (HasWarning(raw, "does not fit this recording as given") || HasWarning(raw, "fit it better")) &&
                              (HasWarning(raw, "--align-shape") || HasWarning(raw, "does not settle the placement"));
      flagged += is_flagged ? 1 : 0;
      ASSERT_TRUE(aligned.shape_alignment);
      const ShapeAlignment& a = *aligned.shape_alignment;
      const double aligned_rms = aligned.metrics.at("object_position_rms");
      std::printf("[alignment] push %u %-18s %s", seed, m.name, a.aligned ? "aligned" : "NOT aligned");
      if (a.aligned) {
        ++aligned_count;
        // Where the contacts leave other placements open, the warning says the frame is unsettled.
        const bool ambiguous = std::any_of(a.notes.begin(), a.notes.end(),
                                           [](const std::string& n) { return n.rfind("ambiguous: ", 0) == 0; });
        ambiguous_count += ambiguous ? 1 : 0;
        if (ambiguous) {
          EXPECT_TRUE(HasWarning(aligned, "does not settle the placement")) << m.name;
          // and gives no sigma for the placement, which is only its curvature there.
          EXPECT_FALSE(a.settled) << m.name;
          EXPECT_TRUE(HasWarning(aligned, "(not settled: ")) << m.name;
        }
        settled_count += a.settled ? 1 : 0;
        // And where they leave a direction to the centroid prior, that another size would fit too.
        const bool weak = std::any_of(a.notes.begin(), a.notes.end(), [](const std::string& n) {
          return n.rfind("the contacts do not fix the position along", 0) == 0;
        });
        weak_count += weak ? 1 : 0;
        if (weak) {
          EXPECT_TRUE(HasWarning(aligned, "a shape of another size or object would fit them as well")) << m.name;
        }
        EXPECT_TRUE(HasWarning(aligned, "aligned it")) << m.name;
        const double outline = OutlineDistance(
            geometry::TransformShape(t.object.shape, a.transform.pose, a.transform.scale, a.transform.mirrored), truth.object.shape);
        outlines.push_back(outline);
        if (a.settled) settled_outlines.push_back(outline);
        ratios.push_back(aligned_rms / rms);
        std::printf(": transform (%6.2f mm, %6.2f mm, %7.2f deg, scale %g) +- (%.2f mm, %.2f mm, %.2f deg); outline error %5.2f mm",
                    a.transform.pose.x * 1e3, a.transform.pose.y * 1e3, a.transform.pose.theta * 180 / M_PI, a.transform.scale,
                    a.sigma.x() * 1e3, a.sigma.y() * 1e3, a.sigma.z() * 180 / M_PI, outline * 1e3);
        if (!a.settled) std::printf(" (not settled: %s)", a.unsettled_by.c_str());
      }
      off_ratios.push_back(raw.metrics.at("object_position_rms") / rms);
      std::printf("; object RMS %.3f mm (true shape %.3f mm, alignment off %.3f mm%s)\n", aligned_rms * 1e3, rms * 1e3,
                  raw.metrics.at("object_position_rms") * 1e3, is_flagged ? ", flagged" : ", NOT flagged");
    }
  }
  std::printf("[alignment] %d aligned as ambiguous, %d with a direction the contacts do not fix\n", ambiguous_count,
              weak_count);
  EXPECT_GT(ambiguous_count, 0);  // the checks above ran
  EXPECT_GT(weak_count, 0);
  std::printf("[alignment] %d cases: %d flagged with alignment off, %d aligned; median outline error %.2f mm, median object "
              "RMS / true-shape RMS %.3f (alignment off: %.2f), worst ratio %.3f\n",
              cases, flagged, aligned_count, Median(outlines) * 1e3, Median(ratios), Median(off_ratios),
              *std::max_element(ratios.begin(), ratios.end()));
  EXPECT_GE(flagged, cases - 1);
  EXPECT_GE(aligned_count, cases - 3);
  EXPECT_LT(Median(ratios), 1.5);
  EXPECT_GT(Median(off_ratios), 1.5);
}

// align_shape "on" on the true shape: it applied its best placement even where the whole graph
// preferred the shape as given (a tri1 push: a turn of 134 degrees, cost 551.8 against 541.3;
// this push: 111.8 degrees, the outline moved by 38 mm), and said nothing. Now it aligns from the
// shape as given then (3.9 mm: the graph's frame within its centroid prior), and says so.
TEST(Alignment, AlignOnKeepsATrueShapeAndSaysWhatItApplied) {
  const push::Trajectory truth = NotchedPush(2.2, 0.0, 2);
  EstimatorConfig cfg = ApplyMeasurementSigmas({}, *truth.measurement_sigmas);
  cfg.align_shape = EstimatorConfig::AlignShape::kOn;
  const EstimationResult r = Estimate(truth, Model::kQs, Mode::kBatch, cfg);
  ASSERT_TRUE(r.shape_alignment && r.shape_alignment->aligned);
  EXPECT_TRUE(HasWarning(r, "the whole graph prefers it to the other placements; align_shape \"on\" refined it from there "
                            "in the graph and aligned it"))
      << (r.warnings.empty() ? "" : r.warnings[0]);
  const double outline = OutlineDistance(geometry::TransformShape(truth.object.shape, r.shape_alignment->transform.pose),
                                         truth.object.shape);
  std::printf("[alignment] align on, true shape: transform (%.2f mm, %.2f mm, %.2f deg), outline moved %.2f mm\n",
              r.shape_alignment->transform.pose.x * 1e3, r.shape_alignment->transform.pose.y * 1e3,
              r.shape_alignment->transform.pose.theta * 180 / M_PI, outline * 1e3);
  EXPECT_LT(outline, 0.01);
}

// A U-shaped block whose tracked origin is the middle of its outer edge, pushed 10 mm beside it
// (`pushgraph simulate`'s default push): the contacts lie 10 mm from the origin against the
// shape's 60 mm radius, and the true shape was refused under "auto" as one that no unit makes
// the size of the finger's path (2 of 5 seeds), the same shape in millimetres every time
// (Registration.AnOriginOnTheOutlineIsNoSizeMismatch). Both are estimated now, the millimetre
// file at scale 0.001.
TEST(Alignment, AUShapeWhoseOriginIsOnItsEdgeIsEstimatedInMetresAndMillimetres) {
  const Shape u = Shape::FromPolygons({{{{0.003, 0.0}, {0.05, 0.0}, {0.05, 0.06}, {0.03, 0.06}, {0.03, 0.02},
                                         {-0.03, 0.02}, {-0.03, 0.06}, {-0.05, 0.06}, {-0.05, 0.0}, {-0.003, 0.0},
                                         {-0.003, 0.006}, {0.003, 0.006}},
                                        {}}});
  for (unsigned seed : {2u, 4u}) {
    const push::Trajectory truth = DefaultPushOf(u, seed);
    EstimatorConfig cfg = ApplyMeasurementSigmas({}, *truth.measurement_sigmas);
    cfg.covariance = false;
    const EstimationResult given = Estimate(truth, Model::kQs, Mode::kBatch, cfg);
    push::Trajectory mm = truth;
    mm.object.shape = geometry::TransformShape(u, Pose2{}, 1000.0);
    const EstimationResult scaled = Estimate(mm, Model::kQs, Mode::kBatch, cfg);
    ASSERT_TRUE(scaled.shape_alignment && scaled.shape_alignment->aligned) << seed;
    EXPECT_EQ(scaled.shape_alignment->transform.scale, 0.001) << seed;
    const double rms = given.metrics.at("object_position_rms"), mm_rms = scaled.metrics.at("object_position_rms");
    const double raw = given.metrics.at("measured_object_position_rms");
    std::printf("[alignment] U, origin on its edge, seed %u: object RMS %.3f mm in metres, %.3f mm in millimetres "
                "(raw %.3f mm)\n", seed, rms * 1e3, mm_rms * 1e3, raw * 1e3);
    EXPECT_LT(rms, 0.5 * raw) << seed;
    EXPECT_LT(mm_rms, 0.5 * raw) << seed;
    // Turned by 37 degrees as well, no unit's window holds it and "auto" refuses it; the message
    // no longer reads as a size error alone.
    push::Trajectory turned = mm;
    turned.object.shape = geometry::TransformShape(u, Pose2{0.0, 0.0, 37.0 * M_PI / 180.0}, 1000.0);
    std::string message = "no error";
    try {
      Estimate(turned, Model::kQs, Mode::kBatch, cfg);
    } catch (const GraphError& e) {
      message = e.what();
    }
    EXPECT_NE(message.find("(at scale 0.001, "), std::string::npos) << message;
    EXPECT_NE(message.find("if the object's origin lies on its edge where the finger pushes, the size may be right and the "
                           "shape's frame not; --align-shape on places it"),
              std::string::npos)
        << message;
  }
}

// An L-shaped plate with a hole, its origin at the outer corner, pushed as `pushgraph simulate`
// does: the contacts of one straight push fit its true shape "better turned by 108.7 to 152
// degrees" (log-likelihood +13 to +18, other placements about as well), and 5 of 6 seeds warned
// so, suggesting the frame was uncertain. The whole graph rejects those placements by 180 to 400
// in cost, and that became a note. Most of that likelihood was the registration's centroid
// prior, which a file whose origin lies on its outline (a CAD corner) is no longer judged by:
// now no suspicion at all, and CP, which has no graph to reject it, no longer warns either.
TEST(Alignment, ASuspicionTheWholeGraphRejectsIsANoteNotAWarning) {
  const Shape l = Shape::FromPolygons({{{{0.0, 0.0}, {0.08, 0.0}, {0.08, 0.03}, {0.03, 0.03}, {0.03, 0.08}, {0.0, 0.08}},
                                        {{{0.02, 0.03}, {0.02, 0.01}, {0.01, 0.01}, {0.01, 0.03}}}}});
  for (unsigned seed : {1u, 4u, 6u}) {
    const push::Trajectory truth = DefaultPushOf(l, seed);
    EstimatorConfig cfg = ApplyMeasurementSigmas({}, *truth.measurement_sigmas);
    cfg.covariance = false;
    const EstimationResult r = Estimate(truth, Model::kQs, Mode::kBatch, cfg);
    ASSERT_TRUE(r.shape_alignment) << seed;
    EXPECT_FALSE(r.shape_alignment->aligned) << seed;
    EXPECT_FALSE(HasWarning(r, "fit it better")) << seed << ": " << (r.warnings.empty() ? "" : r.warnings[0]);
    const EstimationResult cp = Estimate(truth, Model::kCp, Mode::kBatch, cfg);
    EXPECT_FALSE(HasWarning(cp, "fit it better")) << seed << ": " << (cp.warnings.empty() ? "" : cp.warnings[0]);
    std::printf("[alignment] L plate, seed %u: object RMS %.3f mm (raw %.3f mm)\n", seed,
                r.metrics.at("object_position_rms") * 1e3, r.metrics.at("measured_object_position_rms") * 1e3);
  }
}

// A force stream read 1 N high throughout (an untared sensor) or with its x and y exchanged: the
// mechanics then "placed" the true notched block elsewhere, by 36 mm along the pushed side (the
// frame check) or 45 mm, and offered to save the moved shape (a hostile user's session). The bias
// is named from the samples before and after the contact stream, and neither is aligned on.
TEST(Alignment, AForceStreamBiasedOrSwappedIsNamedAndNotAlignedOn) {
  const push::Trajectory clean = DefaultPushOf(geometry::LoadShapeJson(kData + "notched_block.json"), 1);
  EstimatorConfig cfg = ApplyMeasurementSigmas({}, *clean.measurement_sigmas);
  cfg.covariance = false;
  for (const char* fault : {"bias", "swapped"}) {
    push::Trajectory t = clean;
    for (auto& f : t.measured.force) {
      if (std::string(fault) == "bias") f.force.x() += 1.0;
      else std::swap(f.force.x(), f.force.y());
    }
    const EstimationResult r = Estimate(t, Model::kQs, Mode::kBatch, cfg);
    ASSERT_TRUE(r.shape_alignment) << fault;
    EXPECT_FALSE(r.shape_alignment->aligned) << fault << ": " << (r.warnings.empty() ? "" : r.warnings[0]);
    EXPECT_TRUE(HasWarning(r, std::string(fault) == "bias" ? "force: the sensor reads a mean (" : "x and y swapped")) << fault;
    EXPECT_FALSE(HasWarning(r, "places it elsewhere")) << fault;
  }
  // The clean stream: no bias named.
  EXPECT_FALSE(HasWarning(Estimate(clean, Model::kQs, Mode::kBatch, cfg), "force: the sensor reads"));
}

// A force stream whose clock is offset from the contact stream's reads the push's force out of
// contact: it was called "a bias, or a sensor stuck at a value?" (0.2 s late: force estimate
// 0.95 N RMS against 0.50 N raw). The offset is named, within a force period (within half a
// contact period under a 20 Hz contact stream), with the shift that undoes it, and the shape is
// not aligned on it; a bias stays a bias, and an offset the bias check does not see says nothing.
TEST(Alignment, AForceStreamOutOfStepWithTheContactsIsNamed) {
  const push::Trajectory clean = DefaultPushOf(geometry::LoadShapeJson(kData + "notched_block.json"), 3);
  EstimatorConfig cfg = ApplyMeasurementSigmas({}, *clean.measurement_sigmas);
  cfg.covariance = false;
  auto shifted = [&](double lag, double bias) {
    push::Trajectory t = clean;
    for (auto& f : t.measured.force) {
      f.t += lag;
      f.force.x() += bias;
    }
    return t;
  };
  auto force_note = [](const EstimationResult& r) {  // the bias or offset warning, if any
    for (const std::string& w : r.warnings)
      if (w.find("force stream looks about") != std::string::npos || w.find("a bias, or") != std::string::npos) return w;
    return std::string();
  };
  auto number_after = [](const std::string& text, const std::string& key) {
    const std::size_t at = text.find(key);
    return at == std::string::npos ? NAN : std::stod(text.substr(at + key.size()));
  };
  for (int thinned : {1, 12}) {  // the contact stream at 250 Hz, and at 20.8 Hz
    for (double lag : {0.1, 0.2, 0.4, -0.2}) {
      push::Trajectory t = shifted(lag, 0.0);
      std::vector<push::PointSample> rows;
      for (std::size_t i = 0; i < t.measured.contact_point.size(); i += thinned) rows.push_back(t.measured.contact_point[i]);
      t.measured.contact_point = rows;
      const EstimationResult r = Estimate(t, Model::kQs, Mode::kBatch, cfg);
      const std::string note = force_note(r);
      ASSERT_NE(note.find("force stream looks about "), std::string::npos) << lag << ": " << note;
      EXPECT_NE(note.find(lag > 0.0 ? " late " : " early "), std::string::npos) << lag << ": " << note;
      const double tolerance = thinned == 1 ? 0.005 : 0.025;
      EXPECT_NEAR(number_after(note, "about "), std::abs(lag), tolerance) << note;
      EXPECT_NEAR(number_after(note, "force stream's time stamps by "), -lag, tolerance) << note;
      ASSERT_TRUE(r.shape_alignment) << lag;
      EXPECT_FALSE(r.shape_alignment->aligned) << lag;
      std::printf("[alignment] contact rows every %d, force stamps %+.2f s: %s\n", thinned, lag,
                  note.substr(0, note.find(':', 8)).c_str());
    }
  }
  // A bias, with or without an offset, is named as the bias; an offset too small for the bias
  // check to see (0.03 s: fewer than 10 samples beyond its 0.05 s margin), and the stream as
  // simulated, say nothing of the force.
  for (double lag : {0.0, 0.2}) {
    const std::string note = force_note(Estimate(shifted(lag, 1.0), Model::kQs, Mode::kBatch, cfg));
    EXPECT_NE(note.find("a bias, or"), std::string::npos) << lag << ": " << note;
  }
  EXPECT_EQ(force_note(Estimate(shifted(0.03, 0.0), Model::kQs, Mode::kBatch, cfg)), "");
  EXPECT_EQ(force_note(Estimate(clean, Model::kQs, Mode::kBatch, cfg)), "");
}

// An object tracker running late against the finger (a camera's latency). Its contacts lie off
// the shape along the push as a shifted shape's do, so the registration "aligns" the true shape
// (unsettled) and the warning names the delay as another cause; object_delay, the latency given,
// makes the estimate the one of the recording in step.
TEST(Alignment, ALateObjectTrackerIsNamedAndObjectDelayUndoesIt) {
  const push::Trajectory clean = DefaultPushOf(geometry::LoadShapeJson(kData + "notched_block.json"), 3);
  EstimatorConfig cfg = ApplyMeasurementSigmas({}, *clean.measurement_sigmas);
  cfg.covariance = false;
  cfg.diagnostics = false;
  const EstimationResult in_step = Estimate(clean, Model::kQs, Mode::kBatch, cfg);
  const double in_step_rms = in_step.metrics.at("object_position_rms");
  for (double delay : {0.1, 0.3}) {
    push::Trajectory late = clean;
    for (push::PoseSample& s : late.measured.object_pose) s.t += delay;
    const EstimationResult as_recorded = Estimate(late, Model::kQs, Mode::kBatch, cfg);
    std::string said;
    for (const std::string& w : as_recorded.warnings)
      if (w.find("--object-delay") != std::string::npos) said = w;
    EXPECT_NE(said.find("tracker running late"), std::string::npos) << delay;
    EstimatorConfig given = cfg;
    given.object_delay = delay;
    const EstimationResult undone = Estimate(late, Model::kQs, Mode::kBatch, given);
    EXPECT_EQ(undone.object_delay, delay);
    const double rms = undone.metrics.at("object_position_rms");
    EXPECT_NEAR(rms, in_step_rms, 1e-4) << delay;  // the same data up to the rounding of t + d - d
    EXPECT_GT(as_recorded.metrics.at("object_position_rms"), 3.0 * rms) << delay;
    ASSERT_TRUE(undone.shape_alignment);
    EXPECT_FALSE(undone.shape_alignment->aligned) << delay;
    std::printf("[alignment] object stamps %.1f s late: object %.2f mm as recorded, %.2f mm with object_delay (%.2f in step)\n",
                delay, as_recorded.metrics.at("object_position_rms") * 1e3, rms * 1e3, in_step_rms * 1e3);
  }
}

// align_scale on a true shape: the continuous scale comes back near 1 (0.9987), not at it, and
// that alone once made the shape "not fit as given" and aligned it by a turn of 180 degrees.
TEST(Alignment, AlignScaleKeepsATrueShape) {
  for (unsigned seed = 2; seed <= 4; ++seed) {
    const push::Trajectory truth = NotchedPush(1.1 * seed, 0.006 * ((seed % 3) - 1.0), seed);
    EstimatorConfig cfg = ApplyMeasurementSigmas({}, *truth.measurement_sigmas);
    cfg.align_scale = true;
    cfg.covariance = false;
    const EstimationResult r = Estimate(truth, Model::kQs, Mode::kBatch, cfg);
    ASSERT_TRUE(r.shape_alignment && r.shape_alignment->checked);
    EXPECT_FALSE(r.shape_alignment->aligned) << "push " << seed << ": " << (r.warnings.empty() ? "" : r.warnings[0]);
    EXPECT_FALSE(HasWarning(r, "does not fit this recording as given")) << "push " << seed;
  }
}

// A push followed by the finger resting against the block for 3.5 s (the simulator's default
// push and noise, `pushgraph simulate --duration 5`): the resting finger's samples are one boundary
// point. Fitted one by one, their cloud was fitted better by a corner of the block's holes: the
// contacts "fit better" by 13 to 20 in log-likelihood on every seed tried, and the true shape was
// aligned, turned by 84 to 111 degrees (object RMS 0.40 -> 0.62 mm on seed 1, 0.49 -> 0.84 mm on an
// 8 s recording). Now the resting samples count as one point with their weight.
TEST(Alignment, AFingerRestingOnTheObjectDoesNotMoveATrueShape) {
  for (unsigned seed : {1u, 4u, 7u}) {
    push::PushPlan plan = DefaultNoisePlan(0.005, 0.05);
    plan.duration = 5.0;
    plan.seed = seed;
    const push::Trajectory truth = push::Simulate(plan).trajectory;
    EstimatorConfig cfg = ApplyMeasurementSigmas({}, *truth.measurement_sigmas);
    cfg.covariance = false;
    const EstimationResult r = Estimate(truth, Model::kQs, Mode::kBatch, cfg);
    ASSERT_TRUE(r.shape_alignment && r.shape_alignment->checked);
    EXPECT_FALSE(r.shape_alignment->aligned) << "seed " << seed << ": " << (r.warnings.empty() ? "" : r.warnings[0]);
    EXPECT_FALSE(HasWarning(r, "fit it better")) << "seed " << seed << ": " << (r.warnings.empty() ? "" : r.warnings[0]);
    std::printf("[alignment] push with a 3.5 s rest, seed %u: object RMS %.3f mm\n", seed,
                r.metrics.at("object_position_rms") * 1e3);
  }
}

// A finger stream in another frame than the object's: the contacts were explained by moving the
// shape onto the finger's path (a simulated ellip2 push with its finger 0.2 m off: "aligned" by
// 126 mm, exit 0, the object 52.7 mm off against 2.9 mm raw). A placement that leaves the tracked
// origin outside the object (its centroid beyond 1.5 radii), like a shape no unit explains, is
// refused under auto, naming the frames; "off" estimates regardless.
TEST(Alignment, AFingerStreamInAnotherFrameIsRefused) {
  for (double dx : {0.15, 0.2, 0.4}) {
    push::Trajectory t = NotchedPush(2.2, 0.0, 2);
    for (auto& f : t.measured.finger_pose) f.pose.x += dx;
    for (auto& c : t.measured.contact_point) c.point.x() += dx;
    EstimatorConfig cfg = ApplyMeasurementSigmas({}, *t.measurement_sigmas);
    cfg.covariance = false;
    std::string message = "no error";
    try {
      Estimate(t, Model::kQs, Mode::kBatch, cfg);
    } catch (const GraphError& e) {
      message = e.what();
    }
    EXPECT_NE(message.find("pose streams"), std::string::npos) << dx << ": " << message;
    EXPECT_NE(message.find("one frame"), std::string::npos) << dx << ": " << message;
    EXPECT_NE(message.find("--align-shape off"), std::string::npos) << dx << ": " << message;
    cfg.align_shape = EstimatorConfig::AlignShape::kOff;
    EXPECT_NO_THROW(Estimate(t, Model::kQs, Mode::kBatch, cfg));
  }
}

// Too little contact to place a shape by: a 4 mm push touching for about 0.1 s. The true shape was
// judged off by 3.4 mm and "aligned" (3.69 mm against 2.60 as given on a rect1 push); now a shape
// is not aligned on under three independent contact samples, and a misfit says why.
TEST(Alignment, TooLittleContactIsNotAlignedOn) {
  push::PushPlan plan = DefaultNoisePlan(0.001, 0.004);
  plan.seed = 3;
  const push::Trajectory truth = push::Simulate(plan).trajectory;
  for (const Misframe& m : {Misframe{"true", {}, 1.0}, Misframe{"30 deg", {0, 0, M_PI / 6}, 1.0}}) {
    push::Trajectory t = truth;
    t.object.shape = FileShape(truth.object.shape, m);
    EstimatorConfig cfg = ApplyMeasurementSigmas({}, *t.measurement_sigmas);
    cfg.covariance = false;
    const EstimationResult r = Estimate(t, Model::kQs, Mode::kBatch, cfg);
    ASSERT_TRUE(r.shape_alignment && r.shape_alignment->checked) << m.name;
    EXPECT_FALSE(r.shape_alignment->aligned) << m.name << ": " << (r.warnings.empty() ? "" : r.warnings[0]);
    if (HasWarning(r, "does not fit this recording as given")) {
      EXPECT_TRUE(HasWarning(r, "too little contact")) << m.name;
    }
  }
}

// Time stamps in milliseconds: the smoothing's and the graph's per-second noise scales are off by
// 1000, so what they prefer places nothing. `pushgraph simulate --duration 3 --seed 7` written in
// milliseconds had its true notched block "aligned" by the frame check (turned by 46.5 degrees,
// 9.4 mm against 6.1 mm as given); now the clock is warned about and nothing is aligned on it.
TEST(Alignment, NothingIsAlignedOnTimeStampsInMilliseconds) {
  for (unsigned seed : {3u, 7u}) {
    push::PushPlan plan = DefaultNoisePlan(0.005, 0.05);
    plan.duration = 3.0;
    plan.seed = seed;
    const push::Trajectory truth = push::Simulate(plan).trajectory;
    for (const Misframe& m : {Misframe{"true", {}, 1.0}, Misframe{"30 deg", {0, 0, M_PI / 6}, 1.0}}) {
      push::Trajectory t = truth;
      t.object.shape = FileShape(truth.object.shape, m);
      for (push::Streams* s : {&t.measured, &*t.ground_truth}) {
        for (auto& x : s->object_pose) x.t *= 1e3;
        for (auto& x : s->finger_pose) x.t *= 1e3;
        for (auto& x : s->contact_point) x.t *= 1e3;
        for (auto& x : s->force) x.t *= 1e3;
      }
      EstimatorConfig cfg = ApplyMeasurementSigmas({}, *t.measurement_sigmas);
      cfg.covariance = false;
      const EstimationResult r = Estimate(t, Model::kQs, Mode::kBatch, cfg);
      ASSERT_FALSE(r.warnings.empty());
      EXPECT_NE(r.warnings[0].find("are the times in milliseconds"), std::string::npos) << r.warnings[0];
      ASSERT_TRUE(r.shape_alignment && r.shape_alignment->checked) << m.name;
      EXPECT_FALSE(r.shape_alignment->aligned) << "seed " << seed << ", " << m.name;
      if (HasWarning(r, "does not fit this recording as given")) {
        EXPECT_TRUE(HasWarning(r, "not aligned on time stamps that read as milliseconds")) << seed << ", " << m.name;
      }
    }
  }
}

// A file in centimetres from end to end: shapes, positions and sigmas agree, so the size and
// units checks pass, but the noise model's scales do not (the default push's notched block in cm
// was "aligned" by a shift of 0.78 "m", 7.8 mm at its true scale). It is named, and nothing is aligned on it.
TEST(Alignment, AFileInCentimetresThroughoutIsNamedAndNotAlignedOn) {
  push::PushPlan plan = DefaultNoisePlan(0.005, 0.05);
  plan.duration = 3.0;
  plan.seed = 3;
  push::Trajectory t = push::Simulate(plan).trajectory;
  constexpr double kCm = 100.0;
  t.object.shape = geometry::TransformShape(t.object.shape, Pose2{}, kCm);
  t.finger.shape = geometry::TransformShape(t.finger.shape, Pose2{}, kCm);
  for (push::Streams* s : {&t.measured, &*t.ground_truth}) {
    for (auto& x : s->object_pose) x.pose.x *= kCm, x.pose.y *= kCm;
    for (auto& x : s->finger_pose) x.pose.x *= kCm, x.pose.y *= kCm;
    for (auto& x : s->contact_point) x.point *= kCm;
  }
  push::MeasurementSigmas& sigma = *t.measurement_sigmas;
  sigma.object_trans *= kCm, sigma.finger_trans *= kCm, sigma.contact *= kCm;
  EstimatorConfig cfg = ApplyMeasurementSigmas({}, sigma);
  cfg.covariance = false;
  const EstimationResult r = Estimate(t, Model::kQs, Mode::kBatch, cfg);
  ASSERT_FALSE(r.warnings.empty());
  EXPECT_NE(r.warnings[0].find("is the whole file in centimetres"), std::string::npos) << r.warnings[0];
  EXPECT_NE(r.warnings[0].find("divide every length by 100"), std::string::npos) << r.warnings[0];
  ASSERT_TRUE(r.shape_alignment && r.shape_alignment->checked);
  EXPECT_FALSE(r.shape_alignment->aligned) << (r.warnings.size() > 1 ? r.warnings[1] : "");
  // A big object in metres pushed by a 5 cm finger (a 2.4 m box read as centimetres, helper's
  // finding) is not named: read in centimetres its probe would be 0.5 mm.
  push::Trajectory big = t;
  big.finger.shape = Shape::Disk(0.05);
  EXPECT_FALSE(HasWarning(Estimate(big, Model::kCp, Mode::kBatch, cfg), "is the whole file in"));
  // The same push in metres says nothing of the kind.
  const push::Trajectory metres = push::Simulate(plan).trajectory;
  const EstimationResult m = Estimate(metres, Model::kQs, Mode::kBatch, ApplyMeasurementSigmas({}, *metres.measurement_sigmas));
  EXPECT_FALSE(HasWarning(m, "is the whole file in"));
}

// A force stream and no contact stream, on pushes with a long approach: the force's noise
// crossed the 0.05 N threshold on most approach steps, so the touching factor held the finger
// against the object from the start (an 8 cm approach: the object dragged 67 mm to the finger,
// 38.5 mm RMS against 7.1 raw), and on the default push with a 3 cm approach the true shape was
// "aligned", turned by 87 degrees. Steps before the first and after the last contact above the
// force's noise are now out of contact.
TEST(Alignment, ContactGatedOnForceAloneSkipsTheApproach) {
  for (const double standoff : {0.03, 0.08}) {
    push::PushPlan plan = DefaultNoisePlan(standoff, 0.03);
    plan.duration = standoff == 0.03 ? 3.0 : 0.0;
    plan.seed = 2;
    push::Trajectory t = push::Simulate(plan).trajectory;
    t.measured.contact_point.clear();
    EstimatorConfig cfg = ApplyMeasurementSigmas({}, *t.measurement_sigmas);
    cfg.covariance = false;
    const EstimationResult r = Estimate(t, Model::kQs, Mode::kBatch, cfg);
    ASSERT_TRUE(r.shape_alignment && r.shape_alignment->checked);
    EXPECT_FALSE(r.shape_alignment->aligned) << standoff << ": " << (r.warnings.empty() ? "" : r.warnings[0]);
    int gated = 0, pushing = 0, wrong = 0;
    for (const StateEstimate& s : r.states) {
      Vec2 f;
      const bool truth = push::TruthForceAt(t.ground_truth->force, s.t, &f) && f.norm() > 0.0;
      gated += s.contact.has_value();
      pushing += truth;
      wrong += s.contact.has_value() != truth;
    }
    std::printf("[alignment] standoff %.2f m, force-gated contact: %d steps gated, %d pushing in the truth, %d differ; "
                "object RMS %.3f mm (raw %.3f)\n", standoff, gated, pushing, wrong, 1e3 * r.metrics.at("object_position_rms"),
                1e3 * r.metrics.at("measured_object_position_rms"));
    EXPECT_LT(wrong, pushing / 3);  // 32 and 12 of 150 (the 3 s push rests against the block with no force)
    EXPECT_LT(r.metrics.at("object_position_rms"), 0.75 * r.metrics.at("measured_object_position_rms"));
  }
}

// A finger passing 4 cm beside the object, with a force stream and no contact stream: one sample
// against the 0.05 N threshold let the sensor's noise gate the finger in (61 % of its samples at
// sigma 0.05 N), so every such step was in contact, the object pulled 2 cm to the finger's path
// (3.25 mm against 2.80 raw, NEES 33) and the true shape "aligned" by 56 mm. A force stream that
// never shows a contact above its noise now leaves the finger untouched, and says so.
TEST(Alignment, AFingerThatNeverTouchesHasNoContact) {
  push::PushPlan miss = DefaultNoisePlan(0.03, 0.05);
  miss.waypoints = {Vec2(0.1, -0.05), Vec2(0.1, 0.05)};  // 4 cm beside the block's side
  miss.seed = 5;
  push::Trajectory passing = push::Simulate(miss).trajectory;
  passing.measured.contact_point.clear();
  for (Mode mode : {Mode::kBatch, Mode::kIncremental}) {
    const EstimationResult p = Estimate(passing, Model::kQs, mode, ApplyMeasurementSigmas({}, *passing.measurement_sigmas));
    for (const StateEstimate& s : p.states) EXPECT_FALSE(s.contact.has_value()) << "t = " << s.t;
    EXPECT_TRUE(HasWarning(p, "no step is in contact"));
    EXPECT_FALSE(p.shape_alignment && p.shape_alignment->aligned);
    EXPECT_LT(p.metrics.at("object_position_rms"), p.metrics.at("measured_object_position_rms"));
  }
  // A 50 g block pushed 8 cm with the paper's 0.5 N force noise: its force never rises above the
  // noise, but the object is seen to move, so the finger is not taken as never touching (it was:
  // no contact or force anywhere, object 2.98 mm against 1.78 with the contact stream).
  push::PushPlan light = DefaultNoisePlan(0.005, 0.08);
  light.object.mass = 0.05;
  light.noise.force.position.sigma = 0.5;
  light.seed = 5;
  push::Trajectory light_push = push::Simulate(light).trajectory;
  light_push.measured.contact_point.clear();
  const EstimationResult l = Estimate(light_push, Model::kQs, Mode::kBatch, ApplyMeasurementSigmas({}, *light_push.measurement_sigmas));
  EXPECT_FALSE(HasWarning(l, "no step is in contact"));
  // A finger turning back at 0.5 m/s in free air: its centred median cuts the turn by 22 mm,
  // and three true samples were dropped as tracker glitches (the finger then 4.5 mm off at the
  // turn against 1.1 raw). The bound grows with the stream's speed.
  push::PushPlan uturn = DefaultNoisePlan(0.03, 0.05);
  uturn.waypoints = {Vec2(0.01, -0.12), Vec2(0.01, -0.07), Vec2(0.01, -0.12)};
  uturn.speed = 0.5;
  uturn.seed = 1;
  const push::Trajectory back = push::Simulate(uturn).trajectory;
  const EstimationResult u = Estimate(back, Model::kQs, Mode::kBatch, ApplyMeasurementSigmas({}, *back.measurement_sigmas));
  EXPECT_FALSE(HasWarning(u, "tracker glitches"));
  EXPECT_LT(u.metrics.at("finger_position_rms"), u.metrics.at("measured_finger_position_rms"));
  // The same push through the object is gated in as before.
  push::PushPlan through = DefaultNoisePlan(0.03, 0.05);
  through.seed = 5;
  push::Trajectory pushing = push::Simulate(through).trajectory;
  pushing.measured.contact_point.clear();
  const EstimationResult q = Estimate(pushing, Model::kQs, Mode::kBatch, ApplyMeasurementSigmas({}, *pushing.measurement_sigmas));
  EXPECT_FALSE(HasWarning(q, "no step is in contact"));
  EXPECT_GT(std::count_if(q.states.begin(), q.states.end(), [](const StateEstimate& s) { return s.contact.has_value(); }), 100);
}

TEST(Alignment, IncrementalModeUsesTheAlignedShape) {
  const push::Trajectory truth = NotchedPush(1.0, 0.0, 5);
  EstimatorConfig cfg = ApplyMeasurementSigmas({}, *truth.measurement_sigmas);
  push::Trajectory t = truth;
  t.object.shape = FileShape(truth.object.shape, {"", {0.015, 0.01, 2.0}, 1.0});
  const EstimationResult reference = Estimate(truth, Model::kQs, Mode::kIncremental, cfg);
  const EstimationResult aligned = Estimate(t, Model::kQs, Mode::kIncremental, cfg);
  ASSERT_TRUE(aligned.shape_alignment && aligned.shape_alignment->aligned);
  EXPECT_FALSE(aligned.shape_alignment->refined);  // fixed during fixed-lag smoothing
  const double rms = reference.metrics.at("object_position_rms"), a = aligned.metrics.at("object_position_rms");
  const EstimationResult batch = Estimate(t, Model::kQs, Mode::kBatch, cfg);
  const double b = batch.metrics.at("object_position_rms"), raw = aligned.metrics.at("measured_object_position_rms");
  std::printf("[alignment] incremental: object RMS %.3f mm aligned, %.3f mm with the true shape; batch aligned %.3f mm; raw %.3f mm\n",
              a * 1e3, rms * 1e3, b * 1e3, raw * 1e3);
  // As the batch estimate with the aligned shape. (Against the true shape's 1.15 mm both are
  // 2.3 to 2.5 mm: the registration leaves the position along the pushed side to its centroid
  // prior. Before the contact point was measured against the outer boundary only, the true
  // shape's estimate was 2.68 mm too: noisy contact rows pulled it onto a hole's edge. Before the
  // incremental mode's fixed frame was solved to convergence it came from the ranking's solve
  // capped at 25 iterations: 3.5 mm with the chain solver.)
  EXPECT_LT(a, 1.1 * b + 1e-4);
  EXPECT_LT(a, 0.5 * raw);
}

TEST(Alignment, DiskRotationIsUnobservableAndReportedSo) {
  push::PushPlan plan;
  plan.object.shape = Shape::RegularPolygon(64, 0.05);  // the simulator's support region is polygonal
  plan.finger.shape = Shape::Disk(0.005);
  plan.object.mass = 0.8;
  plan.object.mu_surface = 0.3;
  plan.finger.mu_contact = 0.3;
  plan.waypoints = push::StraightPushPath(plan, 0.3, 0.01, 0.005, 0.06);
  plan.noise = push::DefaultNoise(push::NoiseKind::kGaussian);
  const push::Trajectory truth = push::Simulate(plan).trajectory;
  push::Trajectory t = truth;
  t.object.shape = geometry::TransformShape(plan.object.shape, Pose2{0.02, -0.01, 0.3});  // the file's origin is not the centre
  const EstimationResult r = Estimate(t, Model::kQs, Mode::kBatch, ApplyMeasurementSigmas({}, *t.measurement_sigmas));
  ASSERT_TRUE(r.shape_alignment && r.shape_alignment->aligned);
  EXPECT_FALSE(r.shape_alignment->rotation_observable);
  EXPECT_EQ(r.shape_alignment->sigma.z(), 0.0);
  const Vec2 centre = geometry::Act(r.shape_alignment->transform.pose, geometry::CoreCentroid(t.object.shape));
  std::printf("[alignment] disk: centre placed at (%.2f, %.2f) mm (truth 0, 0)\n", centre.x() * 1e3, centre.y() * 1e3);
  // Measured 1.56 mm (chain solver, final cost 616.3) and 1.37 mm (Ceres, 619.7: another
  // minimum); the file's origin is 22 mm from the centre.
  EXPECT_LT(centre.norm(), 2e-3);
}

TEST(Diagnostics, AHealthyEstimateHasChiSquaresNearTheirExpectation) {
  const push::Trajectory t = NotchedPush(0.9, 0.0, 7);
  const EstimationResult r = Estimate(t, Model::kQs, Mode::kBatch, ApplyMeasurementSigmas({}, *t.measurement_sigmas));
  ASSERT_TRUE(r.diagnostics);
  const Diagnostics& d = *r.diagnostics;
  EXPECT_TRUE(d.expected_from_covariance);
  for (const FactorStatistics& f : d.factors) {
    std::printf("[diagnostics] healthy %-18s blocks %5d dof %5d chi2 %9.2f expected %9.2f ratio %.2f\n", f.type.c_str(),
                f.count, f.dof, f.chi2, f.expected, f.Ratio());
    if (f.type == "object_pose" || f.type == "finger_pose" || f.type == "force" || f.type == "contact_point") {
      EXPECT_GT(f.Ratio(), 0.6) << f.type;
      EXPECT_LT(f.Ratio(), 1.6) << f.type;
    }
  }
  EXPECT_TRUE(d.causes.empty()) << d.causes.front();
  EXPECT_LT(d.penetration_share, 0.1);
  EXPECT_LT(std::abs(d.measured_gap_median), 1.5e-3);
}

TEST(Diagnostics, AWrongProbeRadiusIsNamed) {
  const push::Trajectory truth = NotchedPush(2.0, 0.005, 8);
  for (double radius : {0.0025, 0.009}) {
    push::Trajectory t = truth;
    t.finger.shape = Shape::Disk(radius);
    const EstimationResult r = Estimate(t, Model::kQs, Mode::kBatch, ApplyMeasurementSigmas({}, *t.measurement_sigmas));
    for (const std::string& w : r.warnings) std::printf("[diagnostics] radius %.1f mm: %s\n", radius * 1e3, w.c_str());
    EXPECT_TRUE(HasWarning(r, "probe radius")) << radius;
    ASSERT_TRUE(r.shape_alignment);
    EXPECT_FALSE(r.shape_alignment->aligned) << "a size error must not be aligned away";
  }
}

TEST(Diagnostics, AFrozenForceSensorIsNamed) {
  push::Trajectory t = NotchedPush(0.5, -0.005, 9);
  // The force sensor sticks at two values (as the MIT rect1 files do) after the first 50 samples.
  for (std::size_t i = 50; i < t.measured.force.size(); ++i) {
    t.measured.force[i].force = i < t.measured.force.size() / 2 ? Vec2(0.8, 0.1) : Vec2(0.2, -0.3);
  }
  const EstimationResult r = Estimate(t, Model::kQs, Mode::kBatch, ApplyMeasurementSigmas({}, *t.measurement_sigmas));
  ASSERT_TRUE(r.diagnostics);
  bool frozen = false;
  for (const SensorFault& f : r.diagnostics->faults) frozen = frozen || (f.stream == "force" && f.kind == "frozen");
  for (const std::string& c : r.diagnostics->causes) std::printf("[diagnostics] frozen force: %s\n", c.c_str());
  EXPECT_TRUE(frozen);
  EXPECT_TRUE(HasWarning(r, "frozen sensor"));
}

// Force spikes (three samples 8 N off, below the 50-times bound that drops a sample outright)
// are named; a 50 kg push's contact onset (0 to 147 N within one 4 ms step, sigma 0.05 N, which
// the estimate follows to within 2 %: 68 sigma) is not (helper-27 N6: "spiking sensor").
TEST(Diagnostics, ForceSpikesAreNamedAndAHeavyPushsOnsetIsNot) {
  auto spikes = [](const EstimationResult& r) {
    for (const SensorFault& f : r.diagnostics->faults)
      if (f.stream == "force" && f.kind == "spikes") return true;
    return false;
  };
  push::Trajectory t = NotchedPush(0.5, -0.005, 10);
  const std::size_t n = t.measured.force.size();
  for (const std::size_t i : {n / 3, n / 2, 2 * n / 3}) t.measured.force[i].force += Vec2(8.0, 0.0);
  const EstimationResult spiked = Estimate(t, Model::kQs, Mode::kBatch, ApplyMeasurementSigmas({}, *t.measurement_sigmas));
  ASSERT_TRUE(spiked.diagnostics);
  for (const std::string& c : spiked.diagnostics->causes) std::printf("[diagnostics] force spikes: %s\n", c.c_str());
  EXPECT_TRUE(spikes(spiked));

  push::PushPlan plan = DefaultNoisePlan(0.005, 0.05);
  plan.object.mass = 50.0;
  plan.seed = 1;
  const push::Trajectory heavy = push::Simulate(plan).trajectory;
  const EstimationResult r = Estimate(heavy, Model::kQs, Mode::kBatch, ApplyMeasurementSigmas({}, *heavy.measurement_sigmas));
  ASSERT_TRUE(r.diagnostics);
  for (const std::string& c : r.diagnostics->causes) {
    std::printf("[diagnostics] 50 kg push: %s\n", c.c_str());
    EXPECT_EQ(c.find("the force sensor's noise is larger than its sigma"), std::string::npos) << c;
  }
  EXPECT_FALSE(spikes(r));
}

}  // namespace
}  // namespace pushgraph::graph
