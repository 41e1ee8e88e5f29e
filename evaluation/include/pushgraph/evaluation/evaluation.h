#pragma once
// The evaluation workflow of Lambert et al. 2019 (Sec. IV-V): many pushes (MIT recordings,
// pushgraph trajectory files, simulated pushes), seeded noise added to their clean streams, the
// estimator run per protocol, and the paper's tables computed from per-trajectory rows of
// sufficient statistics (sums, counts, maxima), so that sharded runs merge bit-identically.
//
//   evaluation::EvaluationOptions options;
//   options.protocols = evaluation::ParseProtocols("table1,fig5");
//   options.simulation.count = 8;                                   // 8 seeded simulated pushes
//   std::vector<evaluation::EvaluationItem> items = evaluation::PlanEvaluation(evaluation::ExpandInputs({"data/abs"}), options);
//   std::vector<evaluation::EvaluationRow> rows = evaluation::RunEvaluation(items, options, /*threads=*/4);
//   for (const evaluation::Table& t : evaluation::MakeTables(rows, options.SettingsJson())) std::cout << evaluation::TableMarkdown(t);
//
// Sharding: ShardItems(items, k, n) keeps the items with index % n == k (indices of the sorted
// list); the rows of all shards, concatenated and given to MakeTables, give the same tables as
// one run over every item (aggregation is in item order, numbers round-trip exactly through
// WriteRows/ReadRows). Solve times (the runtime protocol) differ from run to run.
//
// Errors: a trajectory that cannot be read or estimated gives a row with `error` set (naming its
// file), counted in the tables' notes; bad options throw EvaluationError.
#include <pushgraph/evaluation/errors.h>
#include <pushgraph/evaluation/inputs.h>
#include <pushgraph/evaluation/rows.h>
#include <pushgraph/evaluation/tables.h>
#include <pushgraph/graph/config.h>
#include <pushgraph/graph/estimator.h>
#include <pushgraph/graph/registration.h>

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace pushgraph::evaluation {

/// The paper's evaluations: Table I (QS batch, Gaussian noise: RMS and marginal sigma per
/// quantity), Table II (QS batch, bimodal noise: force magnitude/direction and contact errors),
/// Fig. 5 (object pose error of raw, CP, SDF, QS, Yu; batch and incremental), occlusion (object
/// stream removed in the middle of the push), consistency (NEES), runtime.
enum class Protocol { kTable1, kTable2, kFig5, kOcclusion, kConsistency, kRuntime };

/// "table1,table2,fig5,occlusion,consistency,runtime" or "all"; throws EvaluationError naming an unknown
/// entry. The result is in the canonical order above, without duplicates.
std::vector<Protocol> ParseProtocols(const std::string& list);
std::string ProtocolName(Protocol protocol);

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
  /// A second simulated group, every contact modelled (SimulationSpec::multi_contact): push i is
  /// simulation's push i (the same line and seed), so wedged pushes compare one to one.
  SimulationSpec multi_contact_simulation;
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
  bool multi_contact_sim = false;  ///< of EvaluationOptions::multi_contact_simulation
  bool plot = false;  ///< among the first plots_per_group items of its group (PlanEvaluation)
  /// The group's shape registration (RegisterGroups): applied to the object's shape before any
  /// estimate, when the group's recordings together say the shape does not fit as given.
  std::optional<graph::ShapeTransform> shape_transform;
  /// The group's reading of its object mesh (RegisterGroups), when its recordings fit another
  /// one than the footprint along z: used instead of the object's shape, before shape_transform.
  std::optional<geometry::Shape> object_shape;
};

/// Items for the files (their kind is detected when evaluated: a file that cannot be read gets
/// a row with the error) followed by options.simulation.count simulated pushes, indexed in that
/// order. The group of a file is the MIT object name in its file name (`shape=NAME`), else its
/// folder's name.
std::vector<EvaluationItem> PlanEvaluation(const std::vector<std::string>& files, const EvaluationOptions& options);

/// Shape registration per group (graph::RegisterShape over all of a group's recordings: one
/// mesh, one tracker, pushes on several sides fix what one push leaves free), before sharding so
/// that every shard uses the same transforms. Groups whose shape does not fit as given get the
/// transform in their items (options.estimator.align_shape "off": none do; "on": every group).
/// A group whose object mesh has other readings (ObjectModel::other_readings) first gets the one
/// its recordings fit (graph::ChooseShapeReading; item.object_shape).
/// Simulated pushes are left alone. Returns one line per group that was checked (what was
/// found, for the user and the tables).
std::vector<std::string> RegisterGroups(std::vector<EvaluationItem>& items, const EvaluationOptions& options);

/// "K/N" with 0 <= K < N; throws EvaluationError otherwise.
std::pair<int, int> ParseShard(const std::string& text);
std::vector<EvaluationItem> ShardItems(const std::vector<EvaluationItem>& items, int shard, int shards);

/// Evaluates one item for every selected protocol; never throws (errors go into the row).
EvaluationRow EvaluateItem(const EvaluationItem& item, const EvaluationOptions& options);

/// Called after each finished item with (finished, total, failed, the item's row).
using EvaluationProgress = std::function<void(int, int, int, const EvaluationRow&)>;

/// EvaluateItem over `items` on `threads` worker threads (<= 0: hardware concurrency); rows in
/// item order. The progress callback is called from the workers, one call at a time.
std::vector<EvaluationRow> RunEvaluation(const std::vector<EvaluationItem>& items, const EvaluationOptions& options,
                                         int threads, const EvaluationProgress& progress = {});

/// The rows file of a run in its output folder: rows.jsonl, or rows-K-of-N.jsonl for shard K of N.
std::string RowsFileName(int shard, int shards);

struct FolderRun {
  std::vector<EvaluationRow> rows;  ///< every item's row (resumed and new), in index order
  std::string rows_path;            ///< out_dir/RowsFileName(...)
  int resumed = 0;                  ///< rows kept from a previous run (resume)
  int failed = 0;                   ///< rows with an error
};

/// RunEvaluation into a folder: `items` (shard header.shard of header.shards of a plan of
/// header.items_total) on `threads` threads, each finished row appended at once to
/// ROWS.partial (flushed: a killed run loses nothing), then ROWS written and the partial file
/// removed. `resume`: rows that a previous run with the same settings and shard left in
/// ROWS.partial or ROWS are kept and their items skipped (failed ones run again); a previous
/// run with other settings is an EvaluationError. Creates out_dir.
FolderRun RunIntoFolder(const std::string& out_dir, const std::vector<EvaluationItem>& items, const RowsHeader& header,
                        const EvaluationOptions& options, int threads, bool resume,
                        const EvaluationProgress& progress = {});

}  // namespace pushgraph::evaluation
