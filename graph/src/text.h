#pragma once
// Internal: small helpers of the graph module's reports (registration, diagnostics).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace pushgraph::graph::internal {

/// printf-style formatting into a string of any length (measured first).
template <class... Args>
std::string Format(const char* fmt, Args... args) {
  const int size = std::snprintf(nullptr, 0, fmt, args...);
  if (size <= 0) return {};
  std::string out(static_cast<std::size_t>(size) + 1, '\0');
  std::snprintf(out.data(), out.size(), fmt, args...);
  out.resize(static_cast<std::size_t>(size));
  return out;
}

/// A step's time for messages: "0.068 s" as given, and for clock times (a recording's Unix
/// time, where %g would print 1.46185921e+09 for every step of a push) to the millisecond with
/// the time since the first step: "1461859211.061 s, 1.336 s after the first step".
inline std::string StepTime(double t, double first, const char* first_is = "the first step") {
  if (std::abs(t) < 1e5) return Format("%.9g s", t);
  return Format("%.3f s, %.3f s after %s", t, t - first, first_is);
}

/// The median (upper middle for an even count); 0 for an empty vector.
inline double Median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const std::size_t m = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + m, v.end());
  return v[m];
}

/// The weighted median: the least value whose weights, with those of the smaller values, reach
/// half the total; 0 for an empty vector.
inline double WeightedMedian(const std::vector<double>& v, const std::vector<double>& w) {
  std::vector<std::size_t> order(v.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return v[a] < v[b]; });
  double total = 0.0;
  for (double x : w) total += x;
  double sum = 0.0;
  for (std::size_t i : order) {
    sum += w[i];
    if (sum >= 0.5 * total) return v[i];
  }
  return order.empty() ? 0.0 : v[order.back()];
}

}  // namespace pushgraph::graph::internal
