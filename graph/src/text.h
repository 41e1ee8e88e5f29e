#pragma once
// Internal: small helpers of the graph module's reports (registration, diagnostics).
#include <algorithm>
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

/// The median (upper middle for an even count); 0 for an empty vector.
inline double Median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const std::size_t m = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + m, v.end());
  return v[m];
}

}  // namespace pushgraph::graph::internal
