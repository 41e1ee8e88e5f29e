#pragma once
// Per-trajectory rows of an evaluation: sufficient statistics (sums, counts, maxima) that merge
// bit-identically across shards, as JSON lines with a header that names the run's settings.
//
//   evaluation::RowsHeader header;
//   std::vector<evaluation::EvaluationRow> rows = evaluation::MergeRows({"out/shard0", "out/shard1"}, &header);
#include <pushgraph/evaluation/errors.h>

#include <map>
#include <string>
#include <vector>

namespace pushgraph::evaluation {

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
/// Throws EvaluationError naming the file and line for malformed content. `cut_last_line_ok`: a last
/// line without its newline that does not parse (an append cut by a kill) is left out instead.
std::vector<EvaluationRow> ReadRows(const std::string& path, RowsHeader* header, bool cut_last_line_ok = false);

/// Reads the rows files (files, or folders holding rows*.jsonl) of the shards of one run and
/// checks they fit together: equal settings and shard count, every shard exactly once, no item
/// twice, items_total items in all. Rows sorted by index. Throws EvaluationError naming the problem.
std::vector<EvaluationRow> MergeRows(const std::vector<std::string>& paths, RowsHeader* header);
/// MergeRows, then the merged rows written to out_dir/rows.jsonl as one run (shard 0 of 1).
std::vector<EvaluationRow> MergeRowsInto(const std::vector<std::string>& paths, const std::string& out_dir,
                                         RowsHeader* header);

}  // namespace pushgraph::evaluation
