// Which reading of an object file a recording's contacts fit (registration.h, ChooseShapeReading):
// a mesh exported with y up is read along z as its side view, and only the contacts can say
// whether its cross-section was meant.
#include "graph_builder.h"
#include "text.h"

#include <pushgraph/graph/errors.h>
#include <pushgraph/graph/registration.h>

#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace pushgraph::graph {

ShapeReadingChoice ChooseShapeReading(const push::Trajectory& trajectory, const std::vector<geometry::Shape>& readings,
                                      const RegistrationOptions& options, const std::vector<std::string>& names) {
  return ChooseShapeReading(std::vector<const push::Trajectory*>{&trajectory}, readings, options, names);
}

ShapeReadingChoice ChooseShapeReading(const std::vector<const push::Trajectory*>& recordings,
                                      const std::vector<geometry::Shape>& readings, const RegistrationOptions& options,
                                      const std::vector<std::string>& names) {
  using internal::Format;
  if (readings.empty()) throw GraphError("ChooseShapeReading: no reading given");
  if (recordings.empty()) throw GraphError("ChooseShapeReading: no recording given");
  ShapeReadingChoice choice;
  const std::size_t n = readings.size();
  choice.checks.resize(n);
  choice.checked.assign(n, false);
  choice.registered_costs.assign(n, std::numeric_limits<double>::quiet_NaN());
  if (n == 1) return choice;
  // The fingers in their own units, as the estimator reads them (a CAD export of both in millimetres).
  std::vector<push::Trajectory> judged;
  for (const push::Trajectory* t : recordings) {
    judged.push_back(*t);
    try {
      std::string note;
      double scale = 1.0;
      if (std::optional<push::Trajectory> scaled = internal::FingerUnits(*t, options, &note, &scale))
        judged.back() = std::move(*scaled);
    } catch (const std::exception&) {
      // The estimate refuses such a trajectory with its own message; here it is judged as given.
    }
  }
  std::vector<const push::Trajectory*> pooled;
  for (const push::Trajectory& t : judged) pooled.push_back(&t);
  auto set_reading = [&](const geometry::Shape& shape) {
    for (push::Trajectory& t : judged) t.object.shape = shape;
  };
  // Each reading as given (the object's units found as the finger's checks find them).
  for (std::size_t k = 0; k < n; ++k) {
    set_reading(readings[k]);
    const geometry::Shape in_metres = internal::WithObjectInMetres(judged.front()).object.shape;
    set_reading(in_metres);
    try {
      choice.checks[k] = CheckShapeFit(pooled, options);
      choice.checked[k] = true;
    } catch (const std::exception&) {
    }
  }
  auto name = [&](std::size_t k) { return names.size() == n ? names[k] : Format("reading %zu", k); };
  auto describe = [&](std::size_t k) {
    return choice.checked[k] ? Format("%s %s (%s)", name(k).c_str(), choice.checks[k].fits ? "fits" : "does not fit",
                                      choice.checks[k].Describe().c_str())
                             : name(k) + " could not be checked";
  };
  if (!choice.checked[0] || choice.checks[0].fits) return choice;
  std::optional<std::size_t> fitting;
  for (std::size_t k = 1; k < n; ++k) {
    if (choice.checked[k] && choice.checks[k].fits &&
        (!fitting || choice.checks[k].gap_median < choice.checks[*fitting].gap_median))
      fitting = k;
  }
  std::string all;
  for (std::size_t k = 0; k < n; ++k) all += (k ? "; " : "") + describe(k);
  choice.reason = "as given, " + all;
  if (fitting) {
    choice.index = static_cast<int>(*fitting);
    return choice;
  }
  // None fits as given (the file's frame or units are off as well): each registered, its costs
  // at reading 0's noise scale so that they compare (a log-likelihood each).
  std::vector<RegistrationResult> registered(n);
  std::vector<bool> ok(n, false);
  RegistrationOptions common = options;
  for (std::size_t k = 0; k < n; ++k) {
    set_reading(readings[k]);
    try {
      registered[k] = RegisterShape(pooled, common);
      ok[k] = true;
      if (k == 0 && common.noise <= 0.0) common.noise = registered[0].noise;
      if (!registered[k].size_mismatch) choice.registered_costs[k] = registered[k].aligned_cost;
    } catch (const std::exception&) {
      if (k == 0) return choice;  // too few contacts to judge: the estimate says so
    }
  }
  std::optional<std::size_t> best;
  for (std::size_t k = 1; k < n; ++k) {
    if (ok[k] && !registered[k].size_mismatch &&
        (!best || registered[k].aligned_cost < registered[*best].aligned_cost))
      best = k;
  }
  if (!best) return choice;
  const double margin = registered[0].size_mismatch ? INFINITY : registered[0].aligned_cost - registered[*best].aligned_cost;
  std::string costs;
  for (std::size_t k = 0; k < n; ++k) {
    costs += (k ? ", " : "") + name(k) +
             (std::isnan(choice.registered_costs[k]) ? std::string(" none") : Format(" %.1f", choice.registered_costs[k]));
  }
  choice.reason += "; aligned to the contacts, their costs (a log-likelihood, lower is better): " + costs;
  // Lower by a clear margin (the estimator's tie margin): the contacts of one push often leave a
  // side view placed against its pushed side about as likely as the cross-section.
  constexpr double kClearMargin = 2.0;
  if (margin >= kClearMargin) {
    choice.index = static_cast<int>(*best);
    choice.by_registration = true;
  }
  return choice;
}

}  // namespace pushgraph::graph
