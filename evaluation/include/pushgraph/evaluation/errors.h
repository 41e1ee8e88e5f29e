#pragma once
// The evaluation module's error: bad evaluation options, configs, rows files and shards.
#include <stdexcept>

namespace pushgraph::evaluation {

/// Thrown for invalid evaluation options or configuration files, rows files that do not fit
/// together, and outputs that cannot be written; what() names the file, line or key.
class EvaluationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace pushgraph::evaluation
