// The pose graph's edges (after Ceres' examples/slam/pose_graph_3d): a measured relative pose
// T_ab between keyframes a and b, residual [R_a^T (p_b - p_a) - t_ab; 2 vec(q_ab^-1 q_a^-1 q_b)]
// weighted by 1/sigma per component. Odometry edges join consecutive keyframes with the SLOT
// trajectory's motion; loop edges carry a verified registration and get a robust loss (in
// PoseGraph) so that one bad edge cannot bend the whole trajectory. Two types so that each edge
// kind has its own factor.
#pragma once

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Geometry>

#include "dlslot/types.hpp"

namespace dlslot::mapper {

using Vector6d = Eigen::Matrix<double, 6, 1>;

struct RelativePoseResidual {
  RelativePoseResidual(const Pose& T_ab, const Vector6d& sigma)
      : t_ab(T_ab.translation()), q_ab(Eigen::Quaterniond(T_ab.rotation()).normalized()), weight(sigma.cwiseInverse()) {}

  template <class T>
  bool operator()(const T* p_a_, const T* q_a_, const T* p_b_, const T* q_b_, T* r_) const {
    Eigen::Map<const Eigen::Matrix<T, 3, 1>> p_a(p_a_), p_b(p_b_);
    Eigen::Map<const Eigen::Quaternion<T>> q_a(q_a_), q_b(q_b_);
    const Eigen::Quaternion<T> q_a_inv = q_a.conjugate();
    const Eigen::Matrix<T, 3, 1> t_est = q_a_inv * (p_b - p_a);
    const Eigen::Quaternion<T> dq = q_ab.template cast<T>().conjugate() * (q_a_inv * q_b);
    Eigen::Map<Eigen::Matrix<T, 6, 1>> r(r_);
    r.template head<3>() = t_est - t_ab.template cast<T>();
    r.template tail<3>() = T(2.0) * dq.vec();
    for (int i = 0; i < 6; ++i) r(i) *= T(weight(i));
    return true;
  }

  Eigen::Vector3d t_ab;
  Eigen::Quaterniond q_ab;
  Vector6d weight;
};

// Consecutive keyframes, from the SLOT trajectory.
struct OdometryEdgeFactor : RelativePoseResidual {
  using RelativePoseResidual::RelativePoseResidual;
  static ceres::CostFunction* Create(const Pose& T_ab, const Vector6d& sigma) {
    return new ceres::AutoDiffCostFunction<OdometryEdgeFactor, 6, 3, 4, 3, 4>(new OdometryEdgeFactor(T_ab, sigma));
  }
};

// A verified loop: the registration of two keyframes far apart along the path.
struct LoopEdgeFactor : RelativePoseResidual {
  using RelativePoseResidual::RelativePoseResidual;
  static ceres::CostFunction* Create(const Pose& T_ab, const Vector6d& sigma) {
    return new ceres::AutoDiffCostFunction<LoopEdgeFactor, 6, 3, 4, 3, 4>(new LoopEdgeFactor(T_ab, sigma));
  }
};

}  // namespace dlslot::mapper
