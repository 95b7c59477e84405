// Odometry factor, eq. 8: e_odo = (X_{t-1}^-1 X_t)^-1 T_{t-1}^t between consecutive ego poses.
#pragma once

#include "backend/pose_factor.hpp"

namespace dlslot::backend {

class OdometryFactor final : public PoseFactor {
 public:
  // T_prev_cur: the odometry's motion from frame t-1 to t; sqrt_info: S with S^T S = Sigma_odo^-1.
  OdometryFactor(const Pose& T_prev_cur, const Matrix6& sqrt_info) : PoseFactor(2, sqrt_info), T_(T_prev_cur) {}
  static ceres::CostFunction* Create(const Pose& T_prev_cur, const Matrix6& sqrt_info) {
    return new OdometryFactor(T_prev_cur, sqrt_info);
  }

 protected:
  // Parameters: X_{t-1}, X_t. (X_{t-1}^-1 X_t)^-1 T = X_t^-1 X_{t-1} T.
  Vector6 error(double const* const* x, Matrix6* const* d) const override {
    return relativeError(fromBlock(x[0]), fromBlock(x[1]), T_, d[0], d[1], nullptr);
  }

 private:
  Pose T_;
};

}  // namespace dlslot::backend
