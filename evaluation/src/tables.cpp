// The paper's tables from evaluation rows (tables.h).
#include "internal.h"

#include <pushgraph/evaluation/tables.h>
#include <pushgraph/geometry/file_output.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

namespace pushgraph::evaluation {

using internal::Fmt;
using internal::HasProtocol;
namespace fs = std::filesystem;

namespace internal {
std::string Fmt(double v, int digits) {
  if (!std::isfinite(v)) return "";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

}  // namespace internal

namespace {

struct Agg {
  const std::map<std::string, double>* s;
  double Get(const std::string& k) const {
    auto it = s->find(k);
    return it == s->end() ? 0.0 : it->second;
  }
  bool Has(const std::string& k) const { return Get(k + "/n") > 0.0; }
  double N(const std::string& k) const { return Get(k + "/n"); }
  double Rms(const std::string& k) const { return std::sqrt(Get(k + "/sq") / N(k)); }
  double Mae(const std::string& k) const { return Get(k + "/abs") / N(k); }
  double Mean(const std::string& k) const { return Get(k + "/sum") / N(k); }
  double Std(const std::string& k) const {
    const double m = Mean(k);
    return std::sqrt(std::max(0.0, Get(k + "/sq") / N(k) - m * m));
  }
  bool HasSigma(const std::string& k) const { return Get(k + "/nvar") > 0.0; }
  double Sigma(const std::string& k) const { return std::sqrt(Get(k + "/var") / Get(k + "/nvar")); }
};

}  // namespace

std::vector<Table> MakeTables(std::vector<EvaluationRow> rows, const std::string& settings_json) {
  const nlohmann::json settings = nlohmann::json::parse(settings_json);
  std::vector<Protocol> protocols;
  for (const auto& p : settings.at("protocols")) protocols.push_back(ParseProtocols(p.get<std::string>()).front());
  std::sort(rows.begin(), rows.end(), [](const EvaluationRow& a, const EvaluationRow& b) { return a.index < b.index; });

  // Sum (or max) per group, in item order: the same order for any sharding.
  std::map<std::string, std::map<std::string, double>> groups;
  std::map<std::string, int> ok, failed;
  for (const EvaluationRow& r : rows) {
    if (!r.error.empty()) {
      ++failed[r.group];
      groups[r.group];
      continue;
    }
    ++ok[r.group];
    auto& g = groups[r.group];
    for (const auto& [k, v] : r.stats) {
      const bool is_max = k.size() >= 4 && (k.compare(k.size() - 4, 4, "/max") == 0 || k.compare(k.size() - 4, 4, "/dim") == 0);
      auto [it, inserted] = g.emplace(k, v);
      if (!inserted) it->second = is_max ? std::max(it->second, v) : it->second + v;
    }
  }
  int total_failed = 0;
  for (const auto& [g, n] : failed) total_failed += n;
  const std::string noise_note =
      "Noise added per axis: " + Fmt(1e3 * settings["noise"]["position_m"].get<double>()) + " mm (object, finger, contact), " +
      Fmt(settings["noise"]["rotation_rad"].get<double>()) + " rad (object orientation), " +
      Fmt(settings["noise"]["force_N"].get<double>()) + " N (force); seed " + settings["seed"].dump() +
      "; the estimator's measurement sigmas equal the added noise.";
  auto common_notes = [&](Table& t) {
    t.notes.push_back(noise_note);
    if (total_failed > 0) t.notes.push_back(std::to_string(total_failed) + " trajectories failed and are left out (see results.md)");
  };
  auto count = [&](const std::string& g) { return std::to_string(ok[g]); };

  std::vector<Table> tables;
  const std::string qs = "gauss.qs.batch";
  if (HasProtocol(protocols, Protocol::kTable1)) {
    Table t{"table1", "Table I: RMS error and mean marginal 1-sigma, QS batch, Gaussian noise", {}, {}, {}};
    t.columns = {"object", "trajectories", "quantity", "unit", "raw RMS", "RMS", "1-sigma", "samples"};
    struct Q {
      const char* key;
      const char* label;
      const char* unit;
      double scale;
    };
    const Q qs_list[] = {{"object_position_moving", "object position (moving)", "mm", 1e3},
                         {"object_rotation_moving", "object rotation (moving)", "rad", 1.0},
                         {"finger_position", "finger position", "mm", 1e3},
                         {"force", "force", "N", 1.0},
                         {"contact", "contact point", "mm", 1e3}};
    for (const auto& [g, s] : groups) {
      const Agg a{&s};
      for (const Q& q : qs_list) {
        const std::string k = qs + "/" + q.key;
        if (!a.Has(k)) continue;
        const std::string raw = "gauss.raw/" + std::string(q.key);
        t.rows.push_back({g, count(g), q.label, q.unit, a.Has(raw) ? Fmt(q.scale * a.Rms(raw)) : "",
                          Fmt(q.scale * a.Rms(k)), a.HasSigma(k) ? Fmt(q.scale * a.Sigma(k)) : "", Fmt(a.N(k), 10)});
      }
    }
    t.notes.push_back("RMS over every estimated step (object pose: only while the object moves, as in the paper); "
                      "positions are 2-D errors |e|, 1-sigma = sqrt(mean(var_x + var_y)) is the RMS the marginal "
                      "covariances predict. Rows without ground truth are absent (MIT recordings have no contact "
                      "stream; rect1's force sensor is frozen, so its force stream is dropped).");
    common_notes(t);
    tables.push_back(t);
  }
  if (HasProtocol(protocols, Protocol::kTable2)) {
    Table t{"table2", "Table II: force and contact recovery, QS batch, bimodal noise", {}, {}, {}};
    t.columns = {"object", "trajectories", "component", "unit", "raw RMSE", "RMSE", "MAE", "sigma", "samples"};
    struct Q {
      const char* key;
      const char* label;
      const char* unit;
      double scale;
    };
    const Q qs_list[] = {{"force_magnitude", "force magnitude", "N", 1.0},
                         {"force_direction", "force direction", "deg", 1.0},
                         {"contact", "contact location", "mm", 1e3}};
    for (const auto& [g, s] : groups) {
      const Agg a{&s};
      for (const Q& q : qs_list) {
        const std::string k = "bimodal.qs.batch/" + std::string(q.key);
        if (!a.Has(k)) continue;
        const std::string raw = "bimodal.raw/" + std::string(q.key);
        t.rows.push_back({g, count(g), q.label, q.unit, a.Has(raw) ? Fmt(q.scale * a.Rms(raw)) : "", Fmt(q.scale * a.Rms(k)),
                          Fmt(q.scale * a.Mae(k)), Fmt(q.scale * a.Std(k)), Fmt(a.N(k), 10)});
      }
    }
    t.notes.push_back("Bimodal noise (mixture of two triangular densities, same sigma) on every stream. Magnitude "
                      "error |f| - |f_true| and direction error (signed angle, only where |f_true| >= 0.25 N); sigma "
                      "is the standard deviation of the signed error (of the distance for contacts).");
    common_notes(t);
    tables.push_back(t);
  }
  const std::string models[] = {"cp", "sdf", "qs", "yu"};
  if (HasProtocol(protocols, Protocol::kFig5)) {
    Table t{"fig5", "Fig. 5: object pose error, mean +- standard deviation over steps, Gaussian noise", {}, {}, {}};
    t.columns = {"object", "trajectories", "method", "mode", "position (mm)", "rotation (rad)", "samples"};
    for (const auto& [g, s] : groups) {
      const Agg a{&s};
      const std::string& group = g;  // a lambda may not capture a structured binding before C++20
      auto add = [&](const std::string& prefix, const std::string& method, const std::string& mode) {
        const std::string p = prefix + "/object_position", r = prefix + "/object_rotation";
        if (!a.Has(p)) return;
        t.rows.push_back({group, count(group), method, mode, Fmt(1e3 * a.Mean(p)) + " +- " + Fmt(1e3 * a.Std(p)),
                          Fmt(a.Mean(r)) + " +- " + Fmt(a.Std(r)), Fmt(a.N(p), 10)});
      };
      add("gauss.raw", "raw", "-");
      for (const std::string mode : {"batch", "incremental"}) {
        for (const std::string& m : models) add("gauss." + m + "." + mode, m == "yu" ? "yu (Yu-Rodriguez)" : m, mode);
      }
    }
    t.notes.push_back("Raw: the noisy object-pose measurements (at their own rate); models: every estimated step.");
    common_notes(t);
    tables.push_back(t);
  }
  if (HasProtocol(protocols, Protocol::kOcclusion)) {
    Table t{"occlusion", "Occlusion: object pose error inside and outside the occluded window", {}, {}, {}};
    t.columns = {"object", "trajectories", "model", "mode", "occluded position RMS (mm)", "occluded rotation RMS (rad)",
                 "visible position RMS (mm)", "visible rotation RMS (rad)", "occluded steps"};
    const std::string mode = settings.value("occlusion_mode", "batch");
    for (const auto& [g, s] : groups) {
      const Agg a{&s};
      for (const std::string& m : models) {
        const std::string p = "occluded." + m + "." + mode;
        if (!a.Has(p + "/object_position_occluded")) continue;
        t.rows.push_back({g, count(g), m, mode, Fmt(1e3 * a.Rms(p + "/object_position_occluded")),
                          Fmt(a.Rms(p + "/object_rotation_occluded")),
                          a.Has(p + "/object_position_visible") ? Fmt(1e3 * a.Rms(p + "/object_position_visible")) : "",
                          a.Has(p + "/object_rotation_visible") ? Fmt(a.Rms(p + "/object_rotation_visible")) : "",
                          Fmt(a.N(p + "/object_position_occluded"), 10)});
      }
    }
    t.notes.push_back("The object stream is removed for the middle " +
                      Fmt(100.0 * settings["occlusion_fraction"].get<double>()) +
                      "% of each push's contact phase (the paper's mid-trajectory occlusion); Gaussian noise elsewhere.");
    common_notes(t);
    tables.push_back(t);
  }
  if (HasProtocol(protocols, Protocol::kConsistency)) {
    Table t{"consistency", "Consistency: mean NEES against its dimension (Gaussian noise)", {}, {}, {}};
    t.columns = {"object", "trajectories", "model", "mode", "quantity", "dimension", "mean NEES", "inside 95% interval", "samples"};
    const std::string quantities[] = {"object_pose", "finger_position", "contact", "force"};
    for (const auto& [g, s] : groups) {
      const Agg a{&s};
      for (const std::string mode : {"batch", "incremental"}) {
        for (const std::string& m : models) {
          for (const std::string& q : quantities) {
            const std::string k = "gauss." + m + "." + mode + "/" + q;
            const double n = a.Get(k + "/nees_n");
            if (n <= 0.0) continue;
            t.rows.push_back({g, count(g), m, mode, q, Fmt(a.Get(k + "/dim")), Fmt(a.Get(k + "/nees") / n),
                              Fmt(100.0 * a.Get(k + "/nees_in") / n, 3) + "%", Fmt(n, 10)});
          }
        }
      }
    }
    t.notes.push_back("NEES = e^T P^-1 e per step; a consistent estimator has mean NEES = dimension and 95% of the steps "
                      "inside the two-sided 95% chi-square interval (dim 2: [0.0506, 7.38], dim 3: [0.216, 9.35]). "
                      "Finger: position block only (its angle is not measured).");
    common_notes(t);
    tables.push_back(t);
  }
  if (HasProtocol(protocols, Protocol::kRuntime)) {
    Table t{"runtime", "Runtime per trajectory and per incremental update", {}, {}, {}};
    t.columns = {"object", "trajectories", "run", "mean steps", "mean solve (s)", "max solve (s)", "updates",
                 "mean update (s)", "max update (s)"};
    for (const auto& [g, s] : groups) {
      const Agg a{&s};
      std::set<std::string> prefixes;
      for (const auto& [k, v] : s) {
        const auto pos = k.find("/time/n");
        if (pos != std::string::npos && pos + 7 == k.size()) prefixes.insert(k.substr(0, pos));
      }
      for (const std::string& p : prefixes) {
        const double n = a.Get(p + "/time/n"), nu = a.Get(p + "/update_time/n");
        t.rows.push_back({g, count(g), p, Fmt(a.Get(p + "/steps/sum") / n), Fmt(a.Get(p + "/time/sum") / n, 3),
                          Fmt(a.Get(p + "/time/max"), 3), nu > 0 ? Fmt(nu, 10) : "",
                          nu > 0 ? Fmt(a.Get(p + "/update_time/sum") / nu, 3) : "",
                          nu > 0 ? Fmt(a.Get(p + "/update_time/max"), 3) : ""});
      }
    }
    t.notes.push_back("Wall time of each graph::Estimate call (single-threaded; trajectories run in parallel, so "
                      "times include contention for cores and memory), covariances included where computed "
                      "(gauss.*.batch with table1/consistency). Run names: NOISE.MODEL.MODE. Times differ from run to run.");
    tables.push_back(t);
  }
  {
    // Self-diagnosis: per group the shape alignment and the health figures, then the worst
    // trajectories with their probable causes.
    Table t{"diagnostics", "Diagnostics: the worst trajectories by their estimate's self-diagnosis", {}, {}, {}};
    t.columns = {"object", "trajectory", "score", "worst factor", "notes"};
    std::vector<const EvaluationRow*> ranked;
    for (const EvaluationRow& r : rows) {
      if (r.error.empty()) ranked.push_back(&r);
    }
    // A push too short for any judged factor type to reach 20 degrees of freedom has no score (0,
    // no worst factor): listed as such after the scored ones and left out of the medians (a
    // 2-sample push ranked as the healthiest, and pulled its group's median to 0).
    auto scored = [](const EvaluationRow& r) { return r.health > 0.0 || !r.worst_factor.empty(); };
    std::stable_sort(ranked.begin(), ranked.end(), [&](const EvaluationRow* a, const EvaluationRow* b) {
      if (scored(*a) != scored(*b)) return scored(*a);
      return a->health > b->health;
    });
    for (std::size_t k = 0; k < ranked.size() && k < 10; ++k) {
      const EvaluationRow& r = *ranked[k];
      std::string notes;
      for (const std::string& n : r.notes) notes += (notes.empty() ? "" : "; ") + n;
      for (char& c : notes) c = c == '|' ? '/' : c;
      if (!scored(r)) {
        notes = "not scored: too few samples (no judged factor type has 20 degrees of freedom)" + (notes.empty() ? "" : "; " + notes);
      }
      t.rows.push_back({r.group, r.name, scored(r) ? Fmt(r.health, 3) : "n/a", r.worst_factor, notes});
    }
    for (const auto& [g, s] : groups) {
      const Agg a{&s};
      std::vector<double> scores;
      int unscored = 0;
      for (const EvaluationRow& r : rows) {
        if (r.group != g || !r.error.empty()) continue;
        if (scored(r)) scores.push_back(r.health);
        else ++unscored;
      }
      std::sort(scores.begin(), scores.end());
      std::string line = scores.empty() ? g + ": no trajectory scored"
                                        : g + ": median score " + Fmt(scores[scores.size() / 2], 3) + " over " +
                                              std::to_string(scores.size()) + (scores.size() == 1 ? " trajectory" : " trajectories");
      if (unscored > 0) line += " (" + std::to_string(unscored) + " of " + count(g) + " too short to score, left out)";
      const double group_aligned = a.Get("shape/group_aligned/sum"), run_aligned = a.Get("shape/run_aligned/sum");
      if (group_aligned > 0) line += "; shape aligned for the group (all its recordings together) in " + Fmt(group_aligned, 6);
      if (run_aligned > 0) line += "; shape aligned by the estimate itself in " + Fmt(run_aligned, 6);
      t.notes.push_back(line + ".");
    }
    t.notes.push_back("Score: the largest chi-square / expected value over the measurement, touching, intersection and "
                      "quasi-static factors of the trajectory's QS batch estimate (Gaussian noise); about 1 is healthy "
                      "(docs/estimation.md, Self-diagnosis). Notes: the estimate's warnings.");
    tables.push_back(t);
  }
  return tables;
}

std::string TableMarkdown(const Table& t) {
  std::ostringstream out;
  out << "### " << t.title << "\n\n|";
  for (const std::string& c : t.columns) out << " " << c << " |";
  out << "\n|";
  for (std::size_t i = 0; i < t.columns.size(); ++i) out << "---|";
  out << "\n";
  for (const auto& r : t.rows) {
    out << "|";
    for (const std::string& c : r) out << " " << c << " |";
    out << "\n";
  }
  if (t.rows.empty()) out << "| (no data) |\n";
  out << "\n";
  for (const std::string& n : t.notes) out << n << "\n\n";
  return out.str();
}

std::string TableCsv(const Table& t) {
  auto quote = [](const std::string& s) {
    if (s.find_first_of(",\"\n") == std::string::npos) return s;
    std::string q = "\"";
    for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
    return q + "\"";
  };
  std::ostringstream out;
  for (std::size_t i = 0; i < t.columns.size(); ++i) out << (i ? "," : "") << quote(t.columns[i]);
  out << "\n";
  for (const auto& r : t.rows) {
    for (std::size_t i = 0; i < r.size(); ++i) out << (i ? "," : "") << quote(r[i]);
    out << "\n";
  }
  return out.str();
}

std::string WriteTables(const std::string& dir, const std::vector<Table>& tables, const std::vector<EvaluationRow>& rows) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw EvaluationError(dir + ": cannot create folder (" + ec.message() + ")");
  auto write = [&](const std::string& name, const std::string& text) {
    const std::string path = (fs::path(dir) / name).string();
    if (const std::string error = geometry::WriteFileAtomically(path, text); !error.empty()) throw EvaluationError(error);
  };
  std::ostringstream all;
  for (const Table& t : tables) {
    const std::string md = TableMarkdown(t);
    write(t.id + ".md", md);
    write(t.id + ".csv", TableCsv(t));
    all << md;
  }
  int failed = 0;
  std::ostringstream errors;
  for (const EvaluationRow& r : rows) {
    if (r.error.empty()) continue;
    ++failed;
    errors << "- " << r.error << "\n";
  }
  all << "### Trajectories: " << rows.size() - failed << " evaluated, " << failed << " failed\n\n" << errors.str();
  if (failed > 0) all << "\n";
  write("results.md", all.str());
  return all.str();
}

}  // namespace pushgraph::evaluation
