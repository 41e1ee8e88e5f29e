#pragma once
// Shared by the evaluation's source files: seeds, the statistics sink and the clean input of an
// item. Not installed.
#include <pushgraph/evaluation/evaluation.h>
#include <pushgraph/graph/estimator.h>
#include <pushgraph/push/trajectory.h>

#include <nlohmann/json_fwd.hpp>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace pushgraph::evaluation::internal {

/// SplitMix64 finalizer (Steele, Lea, Flood 2014): independent seeds from (seed, index).
std::uint64_t SplitMix(std::uint64_t x);
/// FNV-1a hash of a name: an item's seed does not depend on its position in the list.
std::uint64_t Fnv1a(const std::string& s);

/// JSON text of `value` (indent < 0: one line). File names in it need not be UTF-8 (a Latin-1
/// path): such bytes become U+FFFD instead of failing the whole output.
std::string DumpJson(const nlohmann::json& value, int indent = -1);

/// Whether `protocol` is among `protocols`.
bool HasProtocol(const std::vector<Protocol>& protocols, Protocol protocol);

/// A time window [t0, t1]; empty when t1 < t0.
struct Window {
  double t0 = 0.0, t1 = -1.0;
  bool Contains(double t) const { return t >= t0 && t <= t1; }
};

/// Sufficient statistics, stored as "PREFIX/QUANTITY/STAT" (rows.h).
class StatSink {
 public:
  explicit StatSink(std::map<std::string, double>* stats) : stats_(stats) {}
  void Error(const std::string& key, double e);
  void Variance(const std::string& key, double var);
  void Nees(const std::string& key, double nees, int dim);
  void Add(const std::string& key, double v) { (*stats_)[key] += v; }
  void Max(const std::string& key, double v);

 private:
  std::map<std::string, double>* stats_;
};

/// One estimate against the trajectory's ground truth (push/scoring.h's rule), under `prefix`.
void AccumulateRun(const push::Trajectory& traj, const graph::EstimationResult& r, const std::string& prefix,
                   const Window& occluded, StatSink& sink);
/// The raw measurements against the same ground truth.
void AccumulateRaw(const push::Trajectory& traj, const std::string& prefix, StatSink& sink);

/// The clean trajectory of an item: its file's ground truth (or streams), the MIT recording
/// with its object model, or the simulated push.
push::Trajectory LoadCleanTrajectory(const EvaluationItem& item, const EvaluationOptions& options);
/// The object model of an MIT recording item (the override, the configuration's objects, or its
/// mesh folder); nullopt for trajectory files and simulated pushes.
std::optional<ObjectModel> MitItemModel(const EvaluationItem& item, const EvaluationOptions& options);
/// The MIT object name of a file ("..._shape=ellip1_..."), else its folder's name.
std::string MitGroup(const std::string& path);

/// "%.*g", empty for NaN and infinities.
std::string Fmt(double v, int digits = 4);

}  // namespace pushgraph::evaluation::internal
