#pragma once
// The paper's tables from evaluation rows: per group, aggregated in item order, as Markdown and
// CSV, written with the list of failed trajectories.
//
//   for (const evaluation::Table& t : evaluation::MakeTables(rows, header.settings_json))
//     std::cout << evaluation::TableMarkdown(t);
#include <pushgraph/evaluation/rows.h>

#include <string>
#include <vector>

namespace pushgraph::evaluation {

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

}  // namespace pushgraph::evaluation
