// Observation factor, eq. 9: e_obs = (X_t^-1 o_t)^-1 b_t between an ego pose and the pose of a
// dynamic object observed from it (b_t: the detected box, lidar frame of X_t).
#pragma once

#include <ceres/sized_cost_function.h>

#include "backend/pose_manifold.hpp"

namespace dlslot::backend {

class ObservationFactor : public ceres::SizedCostFunction<6, kPoseSize, kPoseSize> {
 public:
  // b: T_lidar_box of the detection; sqrt_info whitens [t_e; Log(R_e)], t_e in the object frame
  // (so the sigmas are along and across the object's heading).
  ObservationFactor(const Pose& b, const Matrix6& sqrt_info) : b_(b), sqrt_info_(sqrt_info) {}
  static ceres::CostFunction* Create(const Pose& b, const Matrix6& sqrt_info) {
    return new ObservationFactor(b, sqrt_info);
  }

  // Parameters: X_t, o_t.
  bool Evaluate(double const* const* p, double* residuals, double** jacobians) const override {
    Matrix6 d_ego, d_obj;
    const bool jac = jacobians != nullptr;
    // (X^-1 o)^-1 b = o^-1 X b
    const Vector6 e = relativeError(fromBlock(p[0]), fromBlock(p[1]), b_, jac ? &d_ego : nullptr,
                                    jac ? &d_obj : nullptr, nullptr);
    Eigen::Map<Vector6> r(residuals);
    r = sqrt_info_ * e;
    if (jac && jacobians[0]) tangentToAmbient(sqrt_info_ * d_ego, p[0], jacobians[0]);
    if (jac && jacobians[1]) tangentToAmbient(sqrt_info_ * d_obj, p[1], jacobians[1]);
    return true;
  }

 private:
  Pose b_;
  Matrix6 sqrt_info_;
};

}  // namespace dlslot::backend
