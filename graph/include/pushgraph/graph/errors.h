#pragma once
// The graph module's error: every invalid estimation input throws it.
#include <stdexcept>

namespace pushgraph::graph {

/// Thrown for invalid estimation input (bad sigmas, unknown model, unusable trajectory, ...);
/// what() names the offending field or sample.
class GraphError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

}  // namespace pushgraph::graph
