#include <pushgraph/push/trajectory.h>

namespace pushgraph::push {

limit_surface::SupportSpec SupportOf(const ObjectDescription& object) {
  limit_surface::SupportSpec spec;
  spec.region = object.shape;
  spec.pressure = object.pressure;
  spec.mass = object.mass;
  spec.mu = object.mu_surface;
  spec.gravity = object.gravity;
  return spec;
}

}  // namespace pushgraph::push
