// Observation factor, eq. 9: e_obs = (X_t^-1 o_t)^-1 b_t between an ego pose and the pose of a
// dynamic object observed from it (b_t: the detected box, lidar frame of X_t).
#pragma once

#include "backend/pose_factor.hpp"

namespace dlslot::backend {

class ObservationFactor : public PoseFactor {
 public:
  // b: T_lidar_box of the detection; sqrt_info whitens [t_e; Log(R_e)], t_e in the object frame
  // (so the sigmas are along and across the object's heading).
  ObservationFactor(const Pose& b, const Matrix6& sqrt_info) : PoseFactor(2, sqrt_info), b_(b) {}
  static ceres::CostFunction* Create(const Pose& b, const Matrix6& sqrt_info) {
    return new ObservationFactor(b, sqrt_info);
  }

 protected:
  // Parameters: X_t, o_t. (X^-1 o)^-1 b = o^-1 X b.
  Vector6 error(double const* const* x, Matrix6* const* d) const override {
    return relativeError(fromBlock(x[0]), fromBlock(x[1]), b_, d[0], d[1], nullptr);
  }

 private:
  Pose b_;
};

}  // namespace dlslot::backend
