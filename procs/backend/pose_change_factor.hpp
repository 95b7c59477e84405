// Pose-change factor, eq. 10, between two consecutive object poses and the pose-change vertex
// c_{t-1}^t (eq. 2: c = o_{t-1}^-1 o_t). The paper prints ((o_{t-1} o_t)^-1 c), a typo for
// e_chg = (o_{t-1}^-1 o_t)^-1 c, which is the identity exactly when eq. 2 holds.
#pragma once

#include "backend/pose_factor.hpp"

namespace dlslot::backend {

class PoseChangeFactor final : public PoseFactor {
 public:
  explicit PoseChangeFactor(const Matrix6& sqrt_info) : PoseFactor(3, sqrt_info) {}
  static ceres::CostFunction* Create(const Matrix6& sqrt_info) { return new PoseChangeFactor(sqrt_info); }

 protected:
  // Parameters: o_{t-1}, o_t, c_{t-1}^t. (o_{t-1}^-1 o_t)^-1 c = o_t^-1 o_{t-1} c.
  Vector6 error(double const* const* x, Matrix6* const* d) const override {
    return relativeError(fromBlock(x[0]), fromBlock(x[1]), fromBlock(x[2]), d[0], d[1], d[2]);
  }
};

}  // namespace dlslot::backend
