// Odometry factor, eq. 8: e_odo = (X_{t-1}^-1 X_t)^-1 T_{t-1}^t between consecutive ego poses.
#pragma once

#include <ceres/sized_cost_function.h>

#include "backend/pose_manifold.hpp"

namespace dlslot::backend {

class OdometryFactor final : public ceres::SizedCostFunction<6, kPoseSize, kPoseSize> {
 public:
  // T_prev_cur: the odometry's motion from frame t-1 to t; sqrt_info: S with S^T S = Sigma_odo^-1.
  OdometryFactor(const Pose& T_prev_cur, const Matrix6& sqrt_info) : T_(T_prev_cur), sqrt_info_(sqrt_info) {}
  static ceres::CostFunction* Create(const Pose& T_prev_cur, const Matrix6& sqrt_info) {
    return new OdometryFactor(T_prev_cur, sqrt_info);
  }

  // Parameters: X_{t-1}, X_t.
  bool Evaluate(double const* const* p, double* residuals, double** jacobians) const override {
    Matrix6 d_prev, d_cur;
    const bool jac = jacobians != nullptr;
    // (X_{t-1}^-1 X_t)^-1 T = X_t^-1 X_{t-1} T
    const Vector6 e = relativeError(fromBlock(p[0]), fromBlock(p[1]), T_, jac ? &d_prev : nullptr,
                                    jac ? &d_cur : nullptr, nullptr);
    Eigen::Map<Vector6> r(residuals);
    r = sqrt_info_ * e;
    if (jac && jacobians[0]) tangentToAmbient(sqrt_info_ * d_prev, p[0], jacobians[0]);
    if (jac && jacobians[1]) tangentToAmbient(sqrt_info_ * d_cur, p[1], jacobians[1]);
    return true;
  }

 private:
  Pose T_;
  Matrix6 sqrt_info_;
};

}  // namespace dlslot::backend
