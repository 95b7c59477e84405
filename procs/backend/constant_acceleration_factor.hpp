// Constant-acceleration prior on three consecutive pose changes c_{t-3}^{t-2}, c_{t-2}^{t-1},
// c_{t-1}^t of one object: the second difference of their translations,
//   e = t(c_{t-1}^t) - 2 t(c_{t-2}^{t-1}) + t(c_{t-3}^{t-2}),
// is the change of the object's acceleration over a frame (jerk x dt^3) and near zero. Eq. 11
// alone (constant velocity) makes a braking or accelerating car lag behind by its acceleration
// times the chain's memory, or, loosened enough to follow it, passes the boxes' noise into the
// velocity; with this factor the chain carries an acceleration and eq. 11's sigma becomes a
// prior on how large it is. The translations are in each change's own start frame, so a car
// turning at a constant rate keeps them constant too.
#pragma once

#include "backend/pose_factor.hpp"

namespace dlslot::backend {

class ConstantAccelerationFactor final : public PoseFactor {
 public:
  explicit ConstantAccelerationFactor(const Matrix6& sqrt_info) : PoseFactor(3, sqrt_info) {}
  // sigmas: x, y, z of the second difference of the per-frame translation (m).
  static ceres::CostFunction* Create(const Eigen::Vector3d& sigmas) {
    Matrix6 S = Matrix6::Zero();
    for (int i = 0; i < 3; ++i) S(i, i) = 1.0 / sigmas[i];
    return new ConstantAccelerationFactor(S);
  }

 protected:
  // Parameters: c_{t-3}^{t-2}, c_{t-2}^{t-1}, c_{t-1}^t. A block's translation moves one for one
  // with its tangent's translation part (pose_manifold.hpp), so the Jacobians are I, -2I, I
  // there and zero on the rotations.
  Vector6 error(double const* const* x, Matrix6* const* d) const override {
    Vector6 e = Vector6::Zero();
    const double weight[3] = {1.0, -2.0, 1.0};
    for (int k = 0; k < 3; ++k) {
      e.head<3>() += weight[k] * Eigen::Map<const Eigen::Vector3d>(x[k]);
      if (d[k]) {
        d[k]->setZero();
        d[k]->topLeftCorner<3, 3>() = weight[k] * Eigen::Matrix3d::Identity();
      }
    }
    return e;
  }
};

}  // namespace dlslot::backend
