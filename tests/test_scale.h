#pragma once
// How much of its work a test does: PUSHGRAPH_TEST_SCALE (default 1). The sanitizer stage
// (`scripts/test.sh --sanitize`) runs every test at 0.25, where ASan and UBSan make code 2 to 5
// times slower: random-case counts shrink with it and the longest real-data loops take a subset.
#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace pushgraph::testing {

inline double TestScale() {
  static const double scale = [] {
    const char* s = std::getenv("PUSHGRAPH_TEST_SCALE");
    if (s == nullptr || *s == '\0') return 1.0;
    const double v = std::atof(s);
    return v > 0.0 ? v : 1.0;
  }();
  return scale;
}

/// n scaled by TestScale(), at least `minimum`.
inline int Scaled(int n, int minimum = 1) {
  return std::max(minimum, static_cast<int>(std::lround(n * TestScale())));
}

}  // namespace pushgraph::testing
