#pragma once
// The evaluation workflow of Lambert et al. 2019 (Sec. IV-V): many pushes (MIT recordings,
// pushgraph trajectory files, simulated pushes), seeded noise added to their clean streams, the
// estimator run per protocol, and the paper's tables computed from per-trajectory rows of
// sufficient statistics (sums, counts, maxima), so that sharded runs merge bit-identically.
//
//   io::EvaluationOptions options;
//   options.protocols = io::ParseProtocols("table1,fig5");
//   options.simulation.count = 8;                                   // 8 seeded simulated pushes
//   std::vector<io::EvaluationItem> items = io::PlanEvaluation(io::ExpandInputs({"data/abs"}), options);
//   std::vector<io::EvaluationRow> rows = io::RunEvaluation(items, options, /*threads=*/4);
//   for (const io::Table& t : io::MakeTables(rows, options.SettingsJson())) std::cout << io::TableMarkdown(t);
//
// Sharding: ShardItems(items, k, n) keeps the items with index % n == k (indices of the sorted
// list); the rows of all shards, concatenated and given to MakeTables, give the same tables as
// one run over every item (aggregation is in item order, numbers round-trip exactly through
// WriteRows/ReadRows). Solve times (the runtime protocol) differ from run to run.
//
// Errors: a trajectory that cannot be read or estimated gives a row with `error` set (naming its
// file), counted in the tables' notes; bad options throw IoError.
#include <pushgraph/geometry/shape.h>
#include <pushgraph/graph/config.h>
#include <pushgraph/graph/estimator.h>
#include <pushgraph/graph/registration.h>
#include <pushgraph/limit_surface/noise.h>
#include <pushgraph/limit_surface/trajectory.h>

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace pushgraph::io {

/// The paper's evaluations: Table I (QS batch, Gaussian noise: RMS and marginal sigma per
/// quantity), Table II (QS batch, bimodal noise: force magnitude/direction and contact errors),
/// Fig. 5 (object pose error of raw, CP, SDF, QS, Yu; batch and incremental), occlusion (object
/// stream removed in the middle of the push), consistency (NEES), runtime.
enum class Protocol { kTable1, kTable2, kFig5, kOcclusion, kConsistency, kRuntime };

/// "table1,table2,fig5,occlusion,consistency,runtime" or "all"; throws IoError naming an unknown
/// entry. The result is in the canonical order above, without duplicates.
std::vector<Protocol> ParseProtocols(const std::string& list);
std::string ProtocolName(Protocol protocol);

/// Noise added to the clean streams (per axis, standard deviations). The paper's Sec. IV values
/// are 0.5 cm and 0.5 N; its 0.5 rad for orientations (29 degrees) is implausible for a vision
/// tracker and would make orientation unobservable from the poses, so 0.05 rad is used.
struct PaperNoise {
  double position = 0.005;  ///< m: object, finger and contact point
  double rotation = 0.05;   ///< rad: object orientation (the finger's angle is not measured)
  double force = 0.5;       ///< N
};

/// Noise model for `kind` (kGaussian or kBimodal) with the given sigmas on every stream.
limit_surface::NoiseModel MakePaperNoise(limit_surface::NoiseKind kind, const PaperNoise& sigmas = {});

/// The trajectory with ground truth = its clean streams (its ground truth when it has one, else
/// its measured streams) and measured = clean + noise (limit_surface::ApplyNoise with `seed`);
/// measurement_sigmas set to the noise's sigmas. Throws IoError for a trajectory without ground
/// truth whose measurement_sigmas say its streams are already noisy (noise added twice, metrics
/// scored against noisy streams).
limit_surface::Trajectory AddNoise(const limit_surface::Trajectory& trajectory, const limit_surface::NoiseModel& noise,
                                   std::uint64_t seed);

/// What a file holds, decided by its content: HDF5 signature or MIT arrays
/// (tip_pose/object_pose/ft_wrench) -> kMitRecording; {"format": "pushgraph-trajectory-1"} ->
/// kTrajectory. Throws IoError naming the file when it is neither (or cannot be read).
enum class InputKind { kMitRecording, kTrajectory };
InputKind DetectInputKind(const std::string& path);

/// An object of the MIT dataset (or any object): shape = support region, uniform pressure.
struct ObjectModel {
  geometry::Shape shape;
  geometry::Shape finger;
  double mass = 0.0;
  double mu_surface = 0.0;
  double mu_contact = 0.25;
};

/// Masses of the dataset's eleven objects from its own shape table: rect1 0.8374, rect2 1.045,
/// rect3 1.2508, ellip1 0.8937, ellip2 1.1104, ellip3 1.3338, tri1 0.8028, tri2 0.9826, tri3
/// 1.1326, hex 0.9827, butter 1.1974 kg. nullopt for other names.
std::optional<double> MitObjectMass(const std::string& object_name);

/// The MIT object named `object_name` with its footprint from `mesh_dir`/NAME.obj (up z), the
/// probe a disk of the radius of `mesh_dir`/tip.obj (a cylinder along y: 4.7 mm), the dataset mass, mu_surface 0.35 (the apparent
/// friction of the ellip1 recordings, dataset README) and mu_contact 0.25. Throws IoError when
/// the name or a mesh is unknown.
ObjectModel MitObjectModel(const std::string& object_name, const std::string& mesh_dir);

/// Simulated pushes: the finger pushes `shape` straight over `push_distance` at `speed`; push
/// direction uniform in [0, 2 pi) and sideways offset uniform in +-offset_fraction of the shape's
/// smaller half-extent, drawn from a generator seeded with (seed, index). Rates: the paper's
/// Sec. V (object 25 Hz, finger/contact/force 250 Hz).
struct SimulationSpec {
  int count = 0;
  std::string name = "sim";  ///< group name in the tables
  ObjectModel object;
  double push_distance = 0.05;  ///< m
  double speed = 0.05;          ///< m/s
  double offset_fraction = 0.5;
  double standoff = 0.005;  ///< m
};

/// The clean (noise-free) simulated push number `index`.
limit_surface::Trajectory SimulatedPush(const SimulationSpec& spec, int index, std::uint64_t seed);

struct EvaluationOptions {
  std::vector<Protocol> protocols = ParseProtocols("all");
  PaperNoise noise;
  std::uint64_t seed = 1;
  /// MIT recordings: each stream keeps at most one sample per 1/mit_rate s (first of each bin,
  /// original time stamps); the paper used 100 Hz. 0 keeps every sample.
  double mit_rate = 100.0;
  /// Occlusion protocol: the object stream is removed for this middle fraction of the push.
  double occlusion_fraction = 0.4;
  graph::Mode occlusion_mode = graph::Mode::kBatch;
  /// Object models for MIT recordings, by object name (the file name's `shape=NAME`, else the
  /// folder name). Names not listed are looked up with MitObjectModel in mesh_dir (or an `obj`
  /// folder beside or above the recording).
  std::map<std::string, ObjectModel> objects;
  /// When set, used for every MIT recording (the command's --object/--finger/--mass/--mu).
  std::optional<ObjectModel> object_override;
  std::string mesh_dir;
  SimulationSpec simulation;
  graph::EstimatorConfig estimator;  ///< measurement sigmas are replaced by the added noise's
  /// Pictures (plot_svg.h) of the first `plots_per_group` items of every group are written into
  /// plot_dir (when set): GROUP-INDEX-fig3.svg, the QS batch trajectory over the footprint with
  /// two-sigma ellipses and forces (the paper's Fig. 3) above the object error over time of raw,
  /// CP, SDF, QS and the baseline (Fig. 5); GROUP-INDEX-occlusion.svg, the same for the occluded
  /// push with the window shaded (Fig. 6).
  std::string plot_dir;
  int plots_per_group = 1;

  /// The settings that must agree between shards (JSON text, for the rows' header).
  std::string SettingsJson() const;
};

struct EvaluationItem {
  int index = 0;         ///< position in the sorted list of all items
  std::string name;      ///< file name, or "sim-0003"
  std::string path;      ///< input file ("" for simulated pushes)
  std::string group;     ///< object name: one table row group
  enum class Source { kFile, kSimulated } source = Source::kSimulated;  ///< kFile: kind by DetectInputKind
  int sim_index = -1;
  bool plot = false;  ///< among the first plots_per_group items of its group (PlanEvaluation)
  /// The group's shape registration (RegisterGroups): applied to the object's shape before any
  /// estimate, when the group's recordings together say the shape does not fit as given.
  std::optional<graph::ShapeTransform> shape_transform;
};

/// Files from paths, folders (recursively: *.h5, *.hdf5, *.json) and glob patterns, sorted and
/// without duplicates. Throws IoError for a path or pattern that matches no file.
std::vector<std::string> ExpandInputs(const std::vector<std::string>& patterns);

/// Items for the files (their kind is detected when evaluated: a file that cannot be read gets
/// a row with the error) followed by options.simulation.count simulated pushes, indexed in that
/// order. The group of a file is the MIT object name in its file name (`shape=NAME`), else its
/// folder's name.
std::vector<EvaluationItem> PlanEvaluation(const std::vector<std::string>& files, const EvaluationOptions& options);

/// Shape registration per group (graph::RegisterShape over all of a group's recordings: one
/// mesh, one tracker, pushes on several sides fix what one push leaves free), before sharding so
/// that every shard uses the same transforms. Groups whose shape does not fit as given get the
/// transform in their items (options.estimator.align_shape "off": none do; "on": every group).
/// Simulated pushes are left alone. Returns one line per group that was checked (what was
/// found, for the user and the tables).
std::vector<std::string> RegisterGroups(std::vector<EvaluationItem>& items, const EvaluationOptions& options);

/// "K/N" with 0 <= K < N; throws IoError otherwise.
std::pair<int, int> ParseShard(const std::string& text);
std::vector<EvaluationItem> ShardItems(const std::vector<EvaluationItem>& items, int shard, int shards);

/// One trajectory's sufficient statistics: key -> value, keys "RUN/QUANTITY/STAT" (e.g.
/// "gauss.qs.batch/object_position/sq"); STAT "max" and "dim" aggregate by maximum, every other
/// by sum.
struct EvaluationRow {
  int index = 0;
  std::string name, group;
  std::string error;  ///< non-empty: the trajectory failed (message names the file)
  int steps = 0;
  std::map<std::string, double> stats;
  /// The self-diagnosis of the trajectory's QS batch estimate with Gaussian noise (the first run
  /// when that protocol is not run): its score (graph::Diagnostics::score), worst factor, and
  /// the estimate's warnings (probable causes, shape alignment).
  double health = 0.0;
  std::string worst_factor;
  std::vector<std::string> notes;
};

/// Evaluates one item for every selected protocol; never throws (errors go into the row).
EvaluationRow EvaluateItem(const EvaluationItem& item, const EvaluationOptions& options);

/// Called after each finished item with (finished, total, failed, the item's row).
using EvaluationProgress = std::function<void(int, int, int, const EvaluationRow&)>;

/// EvaluateItem over `items` on `threads` worker threads (<= 0: hardware concurrency); rows in
/// item order. The progress callback is called from the workers, one call at a time.
std::vector<EvaluationRow> RunEvaluation(const std::vector<EvaluationItem>& items, const EvaluationOptions& options,
                                         int threads, const EvaluationProgress& progress = {});

/// Rows as JSON lines: a header line {"pushgraph_evaluation_rows": 1, "shard": K, "shards": N,
/// "items_total": T, "settings": {...}} then one line per row.
struct RowsHeader {
  int shard = 0, shards = 1, items_total = 0;
  std::string settings_json;
};
void WriteRows(const std::string& path, const RowsHeader& header, const std::vector<EvaluationRow>& rows);
/// Appends one row line to a rows file (WriteRows wrote its header) and flushes it to disk: a
/// run's finished rows survive a kill (`pushgraph evaluate --resume`).
void AppendRow(const std::string& path, const EvaluationRow& row);
/// Throws IoError naming the file and line for malformed content. `cut_last_line_ok`: a last
/// line without its newline that does not parse (an append cut by a kill) is left out instead.
std::vector<EvaluationRow> ReadRows(const std::string& path, RowsHeader* header, bool cut_last_line_ok = false);

/// Reads the rows files (files, or folders holding rows*.jsonl) of the shards of one run and
/// checks they fit together: equal settings and shard count, every shard exactly once, no item
/// twice, items_total items in all. Rows sorted by index. Throws IoError naming the problem.
std::vector<EvaluationRow> MergeRows(const std::vector<std::string>& paths, RowsHeader* header);

struct Table {
  std::string id;     ///< "table1", ... (file names)
  std::string title;
  std::vector<std::string> columns;
  std::vector<std::vector<std::string>> rows;
  std::vector<std::string> notes;
};

/// The tables of the protocols listed in `settings_json` (EvaluationOptions::SettingsJson, or a
/// rows header's), aggregated per group over the rows in index order; failed rows are counted
/// in the notes.
std::vector<Table> MakeTables(std::vector<EvaluationRow> rows, const std::string& settings_json);
std::string TableMarkdown(const Table& table);
std::string TableCsv(const Table& table);

/// Writes ID.md and ID.csv per table, and results.md (every table plus the list of failed
/// trajectories) into `dir`, creating it. Returns the text of results.md.
std::string WriteTables(const std::string& dir, const std::vector<Table>& tables, const std::vector<EvaluationRow>& rows);

}  // namespace pushgraph::io
