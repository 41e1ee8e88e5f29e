#pragma once
// The push module's error: invalid pushing specs, push plans, noise models and trajectories.
#include <stdexcept>

namespace pushgraph::push {

/// Thrown for an invalid pushing spec, plan or noise model (negative speed, NaN, a path that
/// misses the object, ...); what() names the offending field. (Invalid masses and friction
/// coefficients are refused by limit_surface::MakeSupport with LimitSurfaceError.)
class PushError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

}  // namespace pushgraph::push
