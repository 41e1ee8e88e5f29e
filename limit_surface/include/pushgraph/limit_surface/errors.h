#pragma once
// The limit_surface module's error: every invalid support, pressure or load throws it.
#include <stdexcept>

namespace pushgraph::limit_surface {

/// Thrown for invalid input (negative mass, NaN, empty region, negative pressure, ...);
/// what() names the offending field.
class LimitSurfaceError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

}  // namespace pushgraph::limit_surface
