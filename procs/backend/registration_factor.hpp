// A measured pose change (not in the paper's graph, which has only box observations): the
// object's own points registered between two scans (object_registration.hpp) measure how it
// moved relative to the sensor, A = b_t b_{t-1}^-1 (b: its pose in the lidar frame). With the
// ego poses and eq. 10 (o_t = o_{t-1} c):
//   A = X_t^-1 o_{t-1} c o_{t-1}^-1 X_{t-1},   e = A_meas^-1 A,
// on the blocks X_{t-1}, X_t, o_{t-1} and the pose-change vertex c. The ego poses are in the
// factor, not in the measurement: the registration runs in the world frame of the ego estimates
// of its time, and a measurement carried there with them would bring the odometry's motion into
// the window once more for every registered object, holding the ego where the odometry put it.
#pragma once

#include "backend/pose_factor.hpp"

namespace dlslot::backend {

class RegistrationFactor final : public PoseFactor {
 public:
  // A_meas and the square-root information of e (registrationMeasurement).
  RegistrationFactor(const Pose& A_meas, const Matrix6& sqrt_info) : PoseFactor(4, sqrt_info), A_meas_(A_meas) {}
  static ceres::CostFunction* Create(const Pose& A_meas, const Matrix6& sqrt_info) {
    return new RegistrationFactor(A_meas, sqrt_info);
  }

 protected:
  // Parameters: X_{t-1}, X_t, o_{t-1}, c. e = B^-1 M Z with B = X_t A_meas, M = o c o^-1 (the
  // object's motion in the world) and Z = X_{t-1}; each block's left perturbation carried into
  // those of B and M.
  Vector6 error(double const* const* x, Matrix6* const* d) const override;

 private:
  Pose A_meas_;
};

// A registration's world-frame motion M (o_t = M o_{t-1}), found with the object's points put
// into the world by the ego poses X_prev (its previous points) and X_cur (its current ones), as
// the factor's measurement A_meas = X_cur^-1 M X_prev with the square-root information of e
// from M's information (world tangent at M; rank-deficient where a direction was not measured).
// With X_prev = X_cur = o it is M as the pose change of a frame at o, o^-1 M o
// (registered_velocity.hpp reads a centre's displacement from it).
struct RegistrationMeasurement {
  Pose A_meas = Pose::Identity();
  Matrix6 sqrt_info = Matrix6::Zero();
};
RegistrationMeasurement registrationMeasurement(const Pose& M, const Matrix6& information, const Pose& X_prev,
                                                const Pose& X_cur);

}  // namespace dlslot::backend
