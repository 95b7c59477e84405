// Point-to-line residual (LOAM eq. (2), A-LOAM's LidarEdgeFactor): an edge point of the
// current scan, moved by T_ref_cur, should lie on an edge line of the reference (previous scan
// or local map). The residual is the point's perpendicular offset from the line, a 3-vector
// whose norm is the distance: r = (I - u u^T) (T p - a).
#pragma once

#include <ceres/sized_cost_function.h>

#include "rigid_motion.hpp"

namespace dlslot::odometry {

class EdgeResidual final : public ceres::SizedCostFunction<3, 6> {
 public:
  // p: point in the current frame; a: a point of the line and u its unit direction, reference
  // frame; motion: shared by the residuals of one problem (see RigidMotion).
  EdgeResidual(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& u, RigidMotion& motion)
      : p_(p), a_(a), P_(Eigen::Matrix3d::Identity() - u * u.transpose()), motion_(motion) {}

  bool Evaluate(double const* const* x, double* residual, double** jacobian) const override {
    Matrix36d J;
    const Eigen::Vector3d q = motion_.at(x[0]).apply(p_, jacobian && jacobian[0] ? &J : nullptr);
    Eigen::Map<Eigen::Vector3d> r(residual);
    r = P_ * (q - a_);
    if (jacobian && jacobian[0]) {
      Eigen::Map<Eigen::Matrix<double, 3, 6, Eigen::RowMajor>> dr(jacobian[0]);
      dr = P_ * J;
    }
    return true;
  }

 private:
  Eigen::Vector3d p_, a_;
  Eigen::Matrix3d P_;  // projector onto the plane perpendicular to the line
  RigidMotion& motion_;
};

}  // namespace dlslot::odometry
