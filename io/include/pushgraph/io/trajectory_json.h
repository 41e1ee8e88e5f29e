#pragma once
// The project's trajectory file ("pushgraph-trajectory-1", JSON):
//
//   {"format": "pushgraph-trajectory-1",
//    "object": {"shape": SHAPE, "mass": kg, "mu_surface": mu, "pressure": "uniform"},
//    "finger": {"shape": SHAPE, "mu_contact": mu_c},
//    "streams": {"object_pose": [[t, x, y, theta], ...], "finger_pose": [[t, x, y, theta], ...],
//                "contact_point": [[t, x, y], ...], "force": [[t, f_x, f_y], ...]},
//    "ground_truth": {... same layout as "streams" ...}}
//
// SHAPE is the shape JSON object of docs/geometry.md. Any stream may be missing or empty;
// `ground_truth` is optional. Reading validates everything and names the file and JSON path of
// the first problem: unknown fields, wrong types, NaN/inf, wrong row lengths, negative mass or
// friction, invalid shapes. Samples out of time order are sorted (stable); duplicate time
// stamps within a stream are an error.
//
//   push::Trajectory t = io::LoadTrajectoryJson("push.json");
//   io::SaveTrajectoryJson(t, "copy.json");
#include <pushgraph/io/errors.h>
#include <pushgraph/push/trajectory.h>

#include <stdexcept>
#include <string>
#include <vector>

namespace pushgraph::io {

inline constexpr const char* kTrajectoryFormat = "pushgraph-trajectory-1";

/// Rows of a stream are sorted by time (stable); when `notes` is given, each stream that needed
/// it gets a line there ("streams.force: sorted 2 rows that came after a later time stamp (first:
/// row [5])") for the caller to show: a large reordering often means a clock glitch.
push::Trajectory LoadTrajectoryJson(const std::string& path, std::vector<std::string>* notes = nullptr);
push::Trajectory ParseTrajectoryJson(const std::string& text, const std::string& source_name = "<string>",
                                              std::vector<std::string>* notes = nullptr);
std::string TrajectoryToJson(const push::Trajectory& trajectory, int indent = 1);
void SaveTrajectoryJson(const push::Trajectory& trajectory, const std::string& path);

}  // namespace pushgraph::io
