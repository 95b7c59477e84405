// Pose-change factor, eq. 10, between two consecutive object poses and the pose-change vertex
// c_{t-1}^t (eq. 2: c = o_{t-1}^-1 o_t). The paper prints ((o_{t-1} o_t)^-1 c), a typo for
// e_chg = (o_{t-1}^-1 o_t)^-1 c, which is the identity exactly when eq. 2 holds.
#pragma once

#include <ceres/sized_cost_function.h>

#include "backend/pose_manifold.hpp"

namespace dlslot::backend {

class PoseChangeFactor final : public ceres::SizedCostFunction<6, kPoseSize, kPoseSize, kPoseSize> {
 public:
  explicit PoseChangeFactor(const Matrix6& sqrt_info) : sqrt_info_(sqrt_info) {}
  static ceres::CostFunction* Create(const Matrix6& sqrt_info) { return new PoseChangeFactor(sqrt_info); }

  // Parameters: o_{t-1}, o_t, c_{t-1}^t.
  bool Evaluate(double const* const* p, double* residuals, double** jacobians) const override {
    Matrix6 d_prev, d_cur, d_change;
    const bool jac = jacobians != nullptr;
    // (o_{t-1}^-1 o_t)^-1 c = o_t^-1 o_{t-1} c
    const Vector6 e = relativeError(fromBlock(p[0]), fromBlock(p[1]), fromBlock(p[2]), jac ? &d_prev : nullptr,
                                    jac ? &d_cur : nullptr, jac ? &d_change : nullptr);
    Eigen::Map<Vector6> r(residuals);
    r = sqrt_info_ * e;
    if (jac && jacobians[0]) tangentToAmbient(sqrt_info_ * d_prev, p[0], jacobians[0]);
    if (jac && jacobians[1]) tangentToAmbient(sqrt_info_ * d_cur, p[1], jacobians[1]);
    if (jac && jacobians[2]) tangentToAmbient(sqrt_info_ * d_change, p[2], jacobians[2]);
    return true;
  }

 private:
  Matrix6 sqrt_info_;
};

}  // namespace dlslot::backend
