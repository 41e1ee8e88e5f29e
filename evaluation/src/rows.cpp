// Evaluation rows as JSON lines (rows.h): written, appended as items finish, read back and
// merged across shards.
#include <pushgraph/evaluation/rows.h>
#include <pushgraph/geometry/file_output.h>

#include <nlohmann/json.hpp>

#include "internal.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <unistd.h>

namespace pushgraph::evaluation {
namespace {
namespace fs = std::filesystem;
}  // namespace

namespace {
nlohmann::json RowJson(const EvaluationRow& r) {
  nlohmann::json j = {{"index", r.index}, {"name", r.name}, {"group", r.group}, {"steps", r.steps}};
  if (!r.error.empty()) j["error"] = r.error;
  j["stats"] = r.stats;
  if (r.health > 0.0) j["health"] = r.health;
  if (!r.worst_factor.empty()) j["worst_factor"] = r.worst_factor;
  if (!r.notes.empty()) j["notes"] = r.notes;
  return j;
}
}  // namespace

void AppendRow(const std::string& path, const EvaluationRow& row) {
  const std::string line = internal::DumpJson(RowJson(row)) + "\n";
  FILE* f = std::fopen(path.c_str(), "a");
  if (f == nullptr) throw EvaluationError(path + ": cannot append a row");
  const bool ok = std::fwrite(line.data(), 1, line.size(), f) == line.size() && std::fflush(f) == 0 && ::fsync(fileno(f)) == 0;
  std::fclose(f);
  if (!ok) throw EvaluationError(path + ": cannot append a row (disk full?)");
}

void WriteRows(const std::string& path, const RowsHeader& header, const std::vector<EvaluationRow>& rows) {
  std::ostringstream out;
  nlohmann::json h = {{"pushgraph_evaluation_rows", 1},
                      {"shard", header.shard},
                      {"shards", header.shards},
                      {"items_total", header.items_total},
                      {"settings", nlohmann::json::parse(header.settings_json)}};
  out << internal::DumpJson(h) << "\n";
  for (const EvaluationRow& r : rows) out << internal::DumpJson(RowJson(r)) << "\n";
  if (const std::string error = geometry::WriteFileAtomically(path, out.str()); !error.empty()) throw EvaluationError(error);
}

std::vector<EvaluationRow> ReadRows(const std::string& path, RowsHeader* header, bool cut_last_line_ok) {
  std::ifstream in(path);
  if (!in) throw EvaluationError(path + ": cannot open rows file");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (cut_last_line_ok && !text.empty() && text.back() != '\n') {
    // A kill during an append leaves a partial last line: drop it unless it is complete JSON.
    const std::size_t start = text.rfind('\n') + 1;  // npos + 1 == 0: a single line
    if (start > 0 && !nlohmann::json::accept(text.substr(start))) text.erase(start);
  }
  std::istringstream lines(text);
  std::vector<EvaluationRow> rows;
  std::string line;
  int line_no = 0;
  while (std::getline(lines, line)) {
    ++line_no;
    if (line.empty()) continue;
    const std::string at = path + ":" + std::to_string(line_no) + ": ";
    try {
      const nlohmann::json j = nlohmann::json::parse(line);
      if (line_no == 1) {
        if (!j.contains("pushgraph_evaluation_rows")) throw EvaluationError(at + "not a pushgraph evaluation rows file (no header)");
        header->shard = j.at("shard").get<int>();
        header->shards = j.at("shards").get<int>();
        header->items_total = j.at("items_total").get<int>();
        header->settings_json = j.at("settings").dump();
        continue;
      }
      EvaluationRow r;
      r.index = j.at("index").get<int>();
      r.name = j.at("name").get<std::string>();
      r.group = j.at("group").get<std::string>();
      r.steps = j.at("steps").get<int>();
      if (j.contains("error")) r.error = j["error"].get<std::string>();
      r.stats = j.at("stats").get<std::map<std::string, double>>();
      if (j.contains("health")) r.health = j["health"].get<double>();
      if (j.contains("worst_factor")) r.worst_factor = j["worst_factor"].get<std::string>();
      if (j.contains("notes")) r.notes = j["notes"].get<std::vector<std::string>>();
      rows.push_back(std::move(r));
    } catch (const nlohmann::json::exception& e) {
      throw EvaluationError(at + e.what());
    }
  }
  if (line_no == 0) throw EvaluationError(path + ": empty rows file");
  return rows;
}

std::vector<EvaluationRow> MergeRows(const std::vector<std::string>& paths, RowsHeader* header) {
  std::vector<std::string> files;
  for (const std::string& p : paths) {
    if (fs::is_directory(p)) {
      std::vector<std::string> found;
      for (const auto& e : fs::directory_iterator(p)) {
        const std::string n = e.path().filename().string();
        if (e.is_regular_file() && n.rfind("rows", 0) == 0 && e.path().extension() == ".jsonl") found.push_back(e.path().string());
      }
      if (found.empty()) throw EvaluationError(p + ": no rows*.jsonl file in this folder");
      std::sort(found.begin(), found.end());
      files.insert(files.end(), found.begin(), found.end());
    } else if (fs::is_regular_file(p)) {
      files.push_back(p);
    } else {
      throw EvaluationError(p + ": no such file or folder");
    }
  }
  if (files.empty()) throw EvaluationError("merge: no rows files given");
  std::vector<EvaluationRow> all;
  std::map<int, std::string> shard_file;
  RowsHeader first;
  for (std::size_t i = 0; i < files.size(); ++i) {
    RowsHeader h;
    std::vector<EvaluationRow> rows = ReadRows(files[i], &h);
    if (i == 0) {
      first = h;
    } else {
      if (h.settings_json != first.settings_json)
        throw EvaluationError(files[i] + ": its settings differ from " + files[0] + "'s (different runs cannot be merged)");
      if (h.shards != first.shards || h.items_total != first.items_total)
        throw EvaluationError(files[i] + ": shard count or item count differs from " + files[0] + "'s");
    }
    if (auto [it, inserted] = shard_file.emplace(h.shard, files[i]); !inserted)
      throw EvaluationError("shard " + std::to_string(h.shard) + "/" + std::to_string(h.shards) + " given twice: " + it->second + " and " + files[i]);
    for (const EvaluationRow& r : rows) {
      if (r.index % h.shards != h.shard)
        throw EvaluationError(files[i] + ": item " + std::to_string(r.index) + " does not belong to shard " + std::to_string(h.shard));
    }
    all.insert(all.end(), rows.begin(), rows.end());
  }
  for (int k = 0; k < first.shards; ++k) {
    if (!shard_file.count(k))
      throw EvaluationError("shard " + std::to_string(k) + "/" + std::to_string(first.shards) + " is missing");
  }
  std::sort(all.begin(), all.end(), [](const EvaluationRow& a, const EvaluationRow& b) { return a.index < b.index; });
  for (std::size_t i = 1; i < all.size(); ++i) {
    if (all[i].index == all[i - 1].index) throw EvaluationError("item " + std::to_string(all[i].index) + " appears twice");
  }
  if (static_cast<int>(all.size()) != first.items_total)
    throw EvaluationError("merge: " + std::to_string(all.size()) + " rows but the run had " + std::to_string(first.items_total) + " items");
  first.shard = 0;
  *header = first;
  return all;
}

std::vector<EvaluationRow> MergeRowsInto(const std::vector<std::string>& paths, const std::string& out_dir,
                                         RowsHeader* header) {
  const std::vector<EvaluationRow> rows = MergeRows(paths, header);
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) throw EvaluationError(out_dir + ": cannot create folder (" + ec.message() + ")");
  RowsHeader merged = *header;
  merged.shard = 0;
  merged.shards = 1;
  WriteRows((fs::path(out_dir) / "rows.jsonl").string(), merged, rows);
  return rows;
}

}  // namespace pushgraph::evaluation
