// Vehicle motion prior on one pose change c_{t-1}^t of a vehicle (car, van, truck, cyclist): a
// wheeled vehicle moves along its own heading (no sideways or vertical slip in its frame) and
// does not keep rolling or pitching, so c's lateral and vertical translation and its roll and
// pitch are near zero; its forward motion and yaw are left to eq. 10-11. This is what ties a
// vehicle's velocity direction to its heading; without it the constant-velocity chain (eq. 11)
// follows the boxes' lateral noise, and a constant ego pitch or yaw-rate error looks like
// objects that climb or drift sideways at a constant rate, which eq. 11 accepts.
#pragma once

#include "backend/pose_factor.hpp"

namespace dlslot::backend {

class VehicleMotionFactor final : public PoseFactor {
 public:
  explicit VehicleMotionFactor(const Matrix6& sqrt_info) : PoseFactor(1, sqrt_info) {}
  // sigmas: lateral (m), vertical (m), roll (rad), pitch (rad) per frame; forward and yaw free.
  static ceres::CostFunction* Create(const Eigen::Vector4d& sigmas) {
    Matrix6 S = Matrix6::Zero();
    S(1, 1) = 1.0 / sigmas[0];
    S(2, 2) = 1.0 / sigmas[1];
    S(3, 3) = 1.0 / sigmas[2];
    S(4, 4) = 1.0 / sigmas[3];
    return new VehicleMotionFactor(S);
  }
  // A vehicle whose chain starts with this pose change starts straight: c's yaw is zero-mean with
  // sigma_rz (rad a frame). Its boxes' headings (0.04 rad each) measure the yaw rate of a young
  // chain only to ~0.004 rad a frame over the window, and left free that rate carries the newest
  // heading, and with it the velocity's direction, ~1 deg off at the window's end; a vehicle
  // turns at the lateral acceleration a at speed v with yaw rate a / v, which bounds it.
  static ceres::CostFunction* StartingStraight(double sigma_rz) {
    Matrix6 S = Matrix6::Zero();
    S(5, 5) = 1.0 / sigma_rz;
    return new VehicleMotionFactor(S);
  }

 protected:
  // Parameter: c_{t-1}^t. The error is c itself ([t; Log R] of B^-1 A Z with A = c, B = Z = I).
  Vector6 error(double const* const* x, Matrix6* const* d) const override {
    return relativeError(fromBlock(x[0]), Pose::Identity(), Pose::Identity(), d[0], nullptr, nullptr);
  }
};

}  // namespace dlslot::backend
