// Constant-velocity factor, eq. 11: e_cons = (c_{t-2}^{t-1})^-1 c_{t-1}^t between consecutive
// pose changes of one object (it moves at constant velocity over a short period). The
// information says how much the per-frame motion may change (acceleration, yaw-rate change).
#pragma once

#include <ceres/sized_cost_function.h>

#include "backend/pose_manifold.hpp"

namespace dlslot::backend {

class ConstantVelocityFactor final : public ceres::SizedCostFunction<6, kPoseSize, kPoseSize> {
 public:
  explicit ConstantVelocityFactor(const Matrix6& sqrt_info) : sqrt_info_(sqrt_info) {}
  static ceres::CostFunction* Create(const Matrix6& sqrt_info) { return new ConstantVelocityFactor(sqrt_info); }

  // Parameters: c_{t-2}^{t-1}, c_{t-1}^t.
  bool Evaluate(double const* const* p, double* residuals, double** jacobians) const override {
    Matrix6 d_prev, d_cur;
    const bool jac = jacobians != nullptr;
    // c_prev^-1 c_cur: the form B^-1 A Z with B = c_prev, A = c_cur, Z = I.
    const Vector6 e = relativeError(fromBlock(p[1]), fromBlock(p[0]), Pose::Identity(), jac ? &d_cur : nullptr,
                                    jac ? &d_prev : nullptr, nullptr);
    Eigen::Map<Vector6> r(residuals);
    r = sqrt_info_ * e;
    if (jac && jacobians[0]) tangentToAmbient(sqrt_info_ * d_prev, p[0], jacobians[0]);
    if (jac && jacobians[1]) tangentToAmbient(sqrt_info_ * d_cur, p[1], jacobians[1]);
    return true;
  }

 private:
  Matrix6 sqrt_info_;
};

}  // namespace dlslot::backend
