#pragma once
// SVG pictures of a push and of its estimation (after Lambert et al. 2019, Fig. 6-8): the
// object's footprint drawn faintly at its estimated poses, the finger at its poses, the paths of
// the object's reference point (measured dots, estimated line, ground truth dashed), two-sigma
// ellipses, force arrows, and an error-over-time panel when the trajectory has ground truth.
// World coordinates are drawn with equal aspect and a scale bar in millimetres.
//
//   push::Trajectory traj = io::LoadTrajectoryJson("push.json");
//   graph::EstimationResult qs = graph::Estimate(traj, graph::Model::kQs, graph::Mode::kBatch);
//   evaluation::TrajectoryPlotOptions options;
//   options.title = "QS batch";                       // every: automatic, about 12 marks
//   evaluation::WriteTrajectorySvg("push.svg", traj, qs, options);
//
//   graph::EstimationResult sdf = graph::Estimate(traj, graph::Model::kSdf, graph::Mode::kBatch);
//   std::vector<evaluation::TimeSeries> err = evaluation::ObjectPositionErrorSeries(traj, {{"SDF", &sdf}, {"QS", &qs}});
//   std::string svg = evaluation::TimeSeriesSvg(err, "object position error", "mm", {{1.0, 1.5}});
//
// Ellipses: the 2x2 position block of a covariance, eigen-decomposed, drawn with semi-axes of
// 2 sqrt(eigenvalue) ("2 sigma along the principal axes"; for a 2-D Gaussian this contour holds
// 86.5% of the probability mass, the chi-square 2-dof value at 4).
// Force arrows: drawn in world length with a fixed millimetres-per-newton scale chosen from the
// largest force of the picture (a 1-2-5 value) and stated in the legend.
// Errors (evaluation::EvaluationError): WriteTrajectorySvg and WriteSvgFile name the path that cannot be written;
// TrajectorySvg and WriteTrajectorySvg refuse a result without states; ObjectPositionErrorSeries
// a null result.
#include <pushgraph/evaluation/errors.h>
#include <pushgraph/graph/estimator.h>
#include <pushgraph/push/trajectory.h>

#include <string>
#include <utility>
#include <vector>

namespace pushgraph::evaluation {

struct TrajectoryPlotOptions {
  int every = 0;         ///< ellipses, force arrows and footprints every N steps (0: automatic, ~10-15 along the push)
  bool ellipses = true;  ///< two-sigma ellipses of object position, finger position, contact point
  bool forces = true;    ///< force arrows (estimated, measured, ground truth) where available
  std::string title;
  int width_px = 960;       ///< at least 480
  bool error_panel = true;  ///< object position error over time (raw and this result) below, with ground truth
};

/// Object and finger trajectories over the object's footprint drawn at its poses, measured vs
/// estimated vs ground truth, two-sigma ellipses, force arrows, plus an error-over-time panel
/// when the trajectory has ground truth.
std::string TrajectorySvg(const push::Trajectory& trajectory, const graph::EstimationResult& result,
                          const TrajectoryPlotOptions& options = {});
void WriteTrajectorySvg(const std::string& path, const push::Trajectory& trajectory,
                        const graph::EstimationResult& result, const TrajectoryPlotOptions& options = {});

struct PushPlotOptions {
  int marks = 12;           ///< about this many marked times along the push (footprints, fingers, forces)
  std::string title;
  int width_px = 960;       ///< at least 480
  bool ground_truth = true; ///< draw the ground truth when the trajectory has it, else the measurements
};

/// A push as it happened, every finger and every contact: the object's footprint at the marked
/// times (the last filled), each finger's shape at its pose there and its path (one colour per
/// finger), every contact point of those times (a finger wedged in a notch shows two), and each
/// finger's force as an arrow from the middle of its contacts. Draws the ground truth (or the
/// measurements without it, or with options.ground_truth false). For a simulated push
/// (`pushgraph simulate --svg`), single- or multi-contact.
std::string PushSvg(const push::Trajectory& trajectory, const PushPlotOptions& options = {});

struct TimeSeries {
  std::string label;
  std::vector<double> t, value;
};

/// Line plot of several series (e.g. object position error of raw, CP, SDF, QS over time),
/// optional shaded windows [t0, t1] (occlusion).
std::string TimeSeriesSvg(const std::vector<TimeSeries>& series, const std::string& title, const std::string& y_label,
                          const std::vector<std::pair<double, double>>& shaded = {});

/// Object position error over time (in mm) of the raw measurements ("raw") and of each result
/// against trajectory.ground_truth by push/scoring.h's rule (interpolated at the sample times, no
/// point where the truth has a gap over 0.1 s).
/// Empty without ground truth.
std::vector<TimeSeries> ObjectPositionErrorSeries(
    const push::Trajectory& trajectory,
    const std::vector<std::pair<std::string, const graph::EstimationResult*>>& results);

/// Writes `svg` to `path`; throws EvaluationError naming the path when it cannot be written.
void WriteSvgFile(const std::string& path, const std::string& svg);

/// One picture of several pictures made by this header's functions, stacked top to bottom.
std::string StackSvgVertically(const std::vector<std::string>& pictures);

}  // namespace pushgraph::evaluation
