// Point-to-plane residual (LOAM eq. (3), A-LOAM's LidarPlaneNormFactor): a plane point of the
// current scan, moved by T_ref_cur, should lie on a plane n . x + d = 0 of the reference
// (previous scan or local map). The residual is the signed distance r = n . (T p) + d.
#pragma once

#include <ceres/sized_cost_function.h>

#include "rigid_motion.hpp"

namespace dlslot::odometry {

class PlaneResidual final : public ceres::SizedCostFunction<1, 6> {
 public:
  // p: point in the current frame; n (unit) and d: the plane in the reference frame; motion:
  // shared by the residuals of one problem (see RigidMotion).
  PlaneResidual(const Eigen::Vector3d& p, const Eigen::Vector3d& n, double d, RigidMotion& motion)
      : p_(p), n_(n), d_(d), motion_(motion) {}

  bool Evaluate(double const* const* x, double* residual, double** jacobian) const override {
    Matrix36d J;
    const Eigen::Vector3d q = motion_.at(x[0]).apply(p_, jacobian && jacobian[0] ? &J : nullptr);
    residual[0] = n_.dot(q) + d_;
    if (jacobian && jacobian[0]) {
      Eigen::Map<Eigen::Matrix<double, 1, 6>> dr(jacobian[0]);
      dr = n_.transpose() * J;
    }
    return true;
  }

 private:
  Eigen::Vector3d p_, n_;
  double d_;
  RigidMotion& motion_;
};

}  // namespace dlslot::odometry
