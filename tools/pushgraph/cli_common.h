#pragma once
// Shared helpers of the `pushgraph` tool's subcommands. Each subcommand lives in its own
// cmd_*.cpp and registers itself on the app; errors are thrown as CliError (or any
// std::exception) and reported by main() as one line on stderr with exit status 1.
#include <pushgraph/geometry/pose.h>
#include <pushgraph/geometry/shape.h>
#include <pushgraph/graph/config.h>
#include <pushgraph/push/trajectory.h>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace pushgraph::cli {

struct CliError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Subcommand registration (one per cmd_*.cpp).
void RegisterDistance(CLI::App& app);
void RegisterPenetration(CLI::App& app);
void RegisterLimitSurface(CLI::App& app);
void RegisterSimulate(CLI::App& app);
void RegisterDemo(CLI::App& app);
void RegisterEstimate(CLI::App& app);
void RegisterEvaluate(CLI::App& app);
void RegisterFootprint(CLI::App& app);
void RegisterMitImport(CLI::App& app);

/// Where the shipped data (shapes) are: $PUSHGRAPH_DATA_DIR if set, else ../share/pushgraph next
/// to the installed executable, else the source tree's data/ folder.
std::string DefaultDataDir();

/// Parses "X,Y,THETA" (finite numbers); `what` names the option in error messages.
geometry::Pose2 ParsePose(const std::string& text, const std::string& what);
/// Parses a comma-separated list of exactly `count` finite numbers.
std::vector<double> ParseNumbers(const std::string& text, std::size_t count, const std::string& what);
/// A CLI11 check for a finite number above `min` (or at least `min` when `inclusive`): rejects
/// NaN and infinities, which CLI11's range checks let through, with a short message ("must be a
/// finite number > 0 (kg), got nan"). `rule` is shown in the message and the help.
CLI::Validator FiniteNumber(double min, bool inclusive, const std::string& rule, double max = INFINITY);
/// The physical flags, with the library's supported ranges (limit_surface/support.h): a mass in
/// (0, 1e6] kg, a friction coefficient in (0, 10] (`zero_allowed`: [0, 10], finger friction).
/// The message names the flag: "--mass: must be a finite number in (0, 1e6] (kg), got 1e308".
CLI::Validator MassValue();
CLI::Validator FrictionValue(bool zero_allowed);
/// A CLI11 transform for an input file that may be a pipe (`<(cat x)`, /dev/stdin): its bytes are
/// copied once into a private temporary file of the same name, whose path the option then holds
/// (readers that look at a file twice, an HDF5 sniff then JSON, or an OBJ's coordinates read
/// again, found the pipe empty: "unexpected end of input"). Regular files pass unchanged.
CLI::Validator ReadOnceInput();
/// `text` with every such temporary path replaced by the path the user gave (for messages).
std::string WithGivenInputPaths(std::string text);
/// The --align-shape option of estimate and evaluate: auto, on or off (empty: not given, the
/// configuration's value stands).
void AddAlignShapeOption(CLI::App* sub, std::string* value);
graph::EstimatorConfig::AlignShape ParseAlignShape(const std::string& value);
/// A shape file named by a flag or argument (`what`, e.g. "--object"): geometry::LoadShapeJson,
/// its errors prefixed with the flag.
/// An object mesh that is a prism along x or y (a y-up export; a can lying on its side) has
/// another reading besides its footprint along z: its cross-section. With `other_readings`, such
/// a mesh's cross-sections are returned there, and its "side view" warning is held back in
/// `side_view` for the caller, whose recording can tell which reading was meant
/// (ChooseObjectReading).
struct MeshReadings {
  std::vector<geometry::Shape> shapes;  ///< the cross-sections
  std::vector<std::string> up;          ///< their axes, "x" or "y"
  std::string side_view;                ///< the warning held back, empty if none
};
geometry::Shape LoadShapeArgument(const std::string& path, const std::string& what,
                                  std::vector<std::string>* warnings = nullptr, MeshReadings* other_readings = nullptr);
/// Which reading of an --object mesh the recording's contacts fit (graph::ChooseShapeReading):
/// sets trajectory.object.shape, says on stderr what was chosen and why, and adds that, or the
/// held-back side-view warning when the footprint along z is kept without fitting, to `warnings`.
/// With align_shape off the footprint along z is kept and the warning said, as before. Returns
/// the up axis chosen when it is not z ("x" or "y"), else "".
std::string ChooseObjectReading(const std::string& path, const MeshReadings& readings, const graph::EstimatorConfig& config,
                                push::Trajectory* trajectory, std::vector<std::string>* warnings);
/// Says on stderr when a shape is outside 1 mm to 2 m across (io::ShapeUnitsWarning), for the
/// commands that take a shape's size as given (limit-surface, simulate); estimate's shape check
/// finds the units itself.
void WarnShapeUnits(const geometry::Shape& shape, const std::string& what, const std::string& path);
/// Formats a double with 17 significant digits (round-trips exactly).
std::string FormatDouble(double value);

/// `--seed N`: a non-negative integer below 2^64 ("-1" is refused, not wrapped around).
CLI::Option* AddSeedOption(CLI::App* app, std::uint64_t* seed, const std::string& help);

/// A file a subcommand reads or writes, with the flag or argument that names it.
struct NamedPath {
  std::string what;  ///< e.g. "-o", "--svg", "TRAJECTORY"
  std::string path;  ///< empty: not given (skipped)
};
/// Refuses, before any work, an output that is one of the inputs or another output: the same
/// path, or the same file under another name (a link, "./a" and "a"). Names both. Also an output
/// that is a folder, or whose folder does not exist or is not writable.
void CheckOutputsAreNew(const std::vector<NamedPath>& inputs, const std::vector<NamedPath>& outputs);
/// Writes JSON with doubles printed to 17 significant digits.
std::string DumpJson(const nlohmann::json& value, int indent = 2);

/// Rewrites "--opt -0.1,0,1" into "--opt=-0.1,0,1" for options that take a value, so that
/// negative numbers are never mistaken for options. `value_options` lists such long options.
std::vector<std::string> JoinNegativeValues(const std::vector<std::string>& args,
                                            const std::vector<std::string>& value_options);

}  // namespace pushgraph::cli
