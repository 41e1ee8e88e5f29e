// The shape frame as a static variable (shape_frame.h): composition of object poses with F.
#include <pushgraph/graph/factors.h>
#include <pushgraph/graph/shape_frame.h>

#include <Eigen/Core>

#include <array>
#include <string>

namespace pushgraph::graph {

using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

ShapeFrameFactor::ShapeFrameFactor(ceres::CostFunction* inner, std::vector<int> object_pose_blocks)
    : inner_(inner), pose_blocks_(std::move(object_pose_blocks)) {
  if (!inner_) throw GraphError("ShapeFrameFactor: no inner factor");
  const auto& sizes = inner_->parameter_block_sizes();
  for (int b : pose_blocks_) {
    if (b < 0 || b >= static_cast<int>(sizes.size()) || sizes[b] != 3) {
      throw GraphError("ShapeFrameFactor: block " + std::to_string(b) + " is not a pose block of the inner factor");
    }
  }
  set_num_residuals(inner_->num_residuals());
  *mutable_parameter_block_sizes() = sizes;
  mutable_parameter_block_sizes()->push_back(3);
}

bool ShapeFrameFactor::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  const auto& sizes = inner_->parameter_block_sizes();
  const int n = static_cast<int>(sizes.size());
  const int m = num_residuals();
  const geometry::Pose2 F{parameters[n][0], parameters[n][1], parameters[n][2]};
  // Composed poses and the Jacobians of the composition.
  std::vector<std::array<double, 3>> composed(pose_blocks_.size());
  std::vector<Eigen::Matrix3d> J_x(pose_blocks_.size()), J_F(pose_blocks_.size());
  std::vector<const double*> inner_params(parameters, parameters + n);
  for (std::size_t k = 0; k < pose_blocks_.size(); ++k) {
    const double* x = parameters[pose_blocks_[k]];
    const geometry::Pose2 placed = geometry::Compose({x[0], x[1], x[2]}, F, &J_x[k], &J_F[k]);
    composed[k] = {placed.x, placed.y, placed.theta};
    inner_params[pose_blocks_[k]] = composed[k].data();
  }
  if (jacobians == nullptr) return inner_->Evaluate(inner_params.data(), residuals, nullptr);
  // Inner Jacobians: the caller's buffers for the other blocks, ours for the composed poses
  // (needed whenever F's Jacobian is).
  const bool want_F = jacobians[n] != nullptr;
  std::vector<RowMatrix> pose_jacobians(pose_blocks_.size(), RowMatrix(m, 3));
  std::vector<double*> inner_jac(jacobians, jacobians + n);
  for (std::size_t k = 0; k < pose_blocks_.size(); ++k) {
    const int b = pose_blocks_[k];
    inner_jac[b] = (jacobians[b] != nullptr || want_F) ? pose_jacobians[k].data() : nullptr;
  }
  if (!inner_->Evaluate(inner_params.data(), residuals, inner_jac.data())) return false;
  Eigen::Map<RowMatrix> JF(jacobians[n], want_F ? m : 0, 3);
  if (want_F) JF.setZero();
  for (std::size_t k = 0; k < pose_blocks_.size(); ++k) {
    const int b = pose_blocks_[k];
    if (jacobians[b] != nullptr) Eigen::Map<RowMatrix>(jacobians[b], m, 3) = pose_jacobians[k] * J_x[k];
    if (want_F) JF += pose_jacobians[k] * J_F[k];
  }
  return true;
}

ShapeFramePrior::ShapeFramePrior(const geometry::Vec2& centroid, double sigma_centroid, double sigma_theta)
    : centroid_(centroid), w_c_(1.0 / sigma_centroid), w_theta_(1.0 / sigma_theta) {
  if (!(sigma_centroid > 0.0) || !(sigma_theta > 0.0)) throw GraphError("ShapeFramePrior: sigmas must be > 0");
  set_num_residuals(3);
  mutable_parameter_block_sizes()->push_back(3);
}

bool ShapeFramePrior::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  const geometry::Pose2 F{parameters[0][0], parameters[0][1], parameters[0][2]};
  Eigen::Matrix<double, 2, 3> J_p_F;
  const geometry::Vec2 placed = geometry::Act(F, centroid_, jacobians ? &J_p_F : nullptr);
  residuals[0] = w_c_ * placed.x();
  residuals[1] = w_c_ * placed.y();
  residuals[2] = w_theta_ * F.theta;
  if (jacobians && jacobians[0]) {
    Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> J(jacobians[0]);
    J.topRows<2>() = w_c_ * J_p_F;
    J.row(2) << 0.0, 0.0, w_theta_;
  }
  return true;
}

}  // namespace pushgraph::graph
