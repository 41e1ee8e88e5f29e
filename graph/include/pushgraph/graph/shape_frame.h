#pragma once
// The object's shape frame as a static variable of the factor graph (shape registration,
// registration.h): a pose F = (x, y, theta) with the shape placed at x_t * F instead of x_t, for
// every step's object pose x_t. Every factor that places the object's shape (C on the object,
// the witness form of C, touching, S, D and the load factor) is wrapped in ShapeFrameFactor,
// which composes its object-pose blocks with F and chains the Jacobians through Compose:
//
//   J_r_x = J_r_x' J_x'_x,   J_r_F = sum over object-pose blocks of J_r_x' J_x'_F,   x' = x * F.
//
// The measurement factors keep the tracker's frame (they measure x_t itself).
//
//   double frame[3] = {0, 0, 0};
//   auto* c = new graph::ShapeFrameFactor(new graph::BoundaryPointFactor(shape, 5e-4), {0});
//   problem.AddResidualBlock(c, nullptr, {x, p, frame});                  // the frame comes last
//   problem.AddResidualBlock(new graph::ShapeFramePrior(centroid, 0.01, 0.2), nullptr, frame);
#include <pushgraph/geometry/pose.h>

#include <ceres/cost_function.h>

#include <memory>
#include <vector>

namespace pushgraph::graph {

/// `inner` with its parameter blocks listed in `object_pose_blocks` (each of size 3) composed
/// with a shape frame F appended as the last parameter block. Takes ownership of `inner`.
class ShapeFrameFactor : public ceres::CostFunction {
 public:
  ShapeFrameFactor(ceres::CostFunction* inner, std::vector<int> object_pose_blocks);
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

 private:
  std::unique_ptr<ceres::CostFunction> inner_;
  std::vector<int> pose_blocks_;
};

/// A weak prior on the shape frame F: the shape's area centroid c (shape coordinates) placed by
/// F stays near the object frame's origin, r = (F * c) / sigma_centroid, and F's angle near 0,
/// r = theta / sigma_theta. It fixes what the contacts and the dynamics leave free (the
/// position along the one side of a block that was pushed), as in RegisterShape.
class ShapeFramePrior : public ceres::CostFunction {
 public:
  ShapeFramePrior(const geometry::Vec2& centroid, double sigma_centroid, double sigma_theta);
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

 private:
  geometry::Vec2 centroid_;
  double w_c_, w_theta_;
};

}  // namespace pushgraph::graph
