#pragma once
// Internal: small helpers of the graph module's reports (registration, diagnostics).
#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

namespace pushgraph::graph::internal {

/// printf-style formatting into a string (messages of at most 320 characters).
template <class... Args>
std::string Format(const char* fmt, Args... args) {
  char buf[320];
  std::snprintf(buf, sizeof buf, fmt, args...);
  return buf;
}

/// The median (upper middle for an even count); 0 for an empty vector.
inline double Median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const std::size_t m = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + m, v.end());
  return v[m];
}

}  // namespace pushgraph::graph::internal
