// A measured pose change (not in the paper's graph, which has only box observations): the
// object's own points registered between two scans (object_registration.hpp) measure its
// pose-change vertex c_{t-1}^t of eq. 10 directly. e = c_meas^-1 c, the form B^-1 A Z with
// A = c, B = c_meas (constant), Z = I; the square-root information comes from the registration's
// (rank-deficient where a direction was not measured).
#pragma once

#include "backend/pose_factor.hpp"

namespace dlslot::backend {

class PoseChangeMeasurementFactor final : public PoseFactor {
 public:
  PoseChangeMeasurementFactor(const Pose& c_meas, const Matrix6& sqrt_info) : PoseFactor(1, sqrt_info), c_meas_(c_meas) {}
  static ceres::CostFunction* Create(const Pose& c_meas, const Matrix6& sqrt_info) {
    return new PoseChangeMeasurementFactor(c_meas, sqrt_info);
  }

 protected:
  // Parameter: c_{t-1}^t.
  Vector6 error(double const* const* x, Matrix6* const* d) const override {
    return relativeError(fromBlock(x[0]), c_meas_, Pose::Identity(), d[0], nullptr, nullptr);
  }

 private:
  Pose c_meas_;
};

// The registration's world-frame motion M (o_t = M o_{t-1}) as a pose-change measurement of an
// object at o_prev: c_meas = o_prev^-1 M o_prev, and the square-root information of
// e = c_meas^-1 c from M's information (world tangent at M) through the numeric Jacobian of e
// with respect to M's tangent.
struct PoseChangeMeasurement {
  Pose c_meas = Pose::Identity();
  Matrix6 sqrt_info = Matrix6::Zero();
};
PoseChangeMeasurement poseChangeMeasurement(const Pose& M, const Matrix6& information, const Pose& o_prev);

}  // namespace dlslot::backend
