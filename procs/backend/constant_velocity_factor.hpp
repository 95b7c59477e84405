// Constant-velocity factor, eq. 11: e_cons = (c_{t-2}^{t-1})^-1 c_{t-1}^t between consecutive
// pose changes of one object (it moves at constant velocity over a short period). The
// information says how much the per-frame motion may change (acceleration, yaw-rate change).
#pragma once

#include "backend/pose_factor.hpp"

namespace dlslot::backend {

class ConstantVelocityFactor final : public PoseFactor {
 public:
  explicit ConstantVelocityFactor(const Matrix6& sqrt_info) : PoseFactor(2, sqrt_info) {}
  static ceres::CostFunction* Create(const Matrix6& sqrt_info) { return new ConstantVelocityFactor(sqrt_info); }

 protected:
  // Parameters: c_{t-2}^{t-1}, c_{t-1}^t. c_prev^-1 c_cur: the form B^-1 A Z with B = c_prev,
  // A = c_cur, Z = I.
  Vector6 error(double const* const* x, Matrix6* const* d) const override {
    return relativeError(fromBlock(x[1]), fromBlock(x[0]), Pose::Identity(), d[1], d[0], nullptr);
  }
};

}  // namespace dlslot::backend
