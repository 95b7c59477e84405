// A vehicle's heading measured from its faces (face_heading.hpp) as a factor on its pose (not in
// the paper's graph). Taken, like a box (eq. 9), against the ego pose of its scan: the heading of
// o_t's x axis in X_t's axes, x = R(X_t)^T R(o_t) e_x, against the measured one,
//   e = remainder(atan2(x_y, x_x) - yaw_meas, pi),
// modulo pi because a fit to the faces does not know front from back (track_front.hpp does).
#pragma once

#include <cmath>

#include "backend/pose_factor.hpp"

namespace dlslot::backend {

class FaceHeadingFactor final : public PoseFactor {
 public:
  // yaw_meas: the heading in the ego's (lidar) axes (rad); sigma: its standard deviation (rad).
  FaceHeadingFactor(double yaw_meas, double sigma) : PoseFactor(2, scalarWhitening(sigma)), yaw_meas_(yaw_meas) {}
  static ceres::CostFunction* Create(double yaw_meas, double sigma) { return new FaceHeadingFactor(yaw_meas, sigma); }

 protected:
  // Parameters: X_t, o_t. Only e[0] is used; the other rows are zero.
  Vector6 error(double const* const* x, Matrix6* const* d) const override {
    const Eigen::Matrix3d RX = fromBlock(x[0]).linear(), Ro = fromBlock(x[1]).linear();
    const Eigen::Vector3d h = RX.transpose() * Ro.col(0);
    const double h2 = h.x() * h.x() + h.y() * h.y();
    Vector6 e = Vector6::Zero();
    e[0] = std::remainder(std::atan2(h.y(), h.x()) - yaw_meas_, M_PI);
    // Tangent perturbations (pose_manifold.hpp) rotate on the left in the world: o's by Exp(dtheta)
    // turns h by phi x h with phi = R(X)^T dtheta, X's by -phi x h. The yaw of h moves by
    // phi_z - h_z (h_x phi_x + h_y phi_y) / |h_xy|^2.
    const Eigen::RowVector3d dyaw(-h.z() * h.x() / h2, -h.z() * h.y() / h2, 1.0);
    const Eigen::RowVector3d J = dyaw * RX.transpose();
    for (int k = 0; k < 2; ++k)
      if (d[k]) d[k]->setZero();
    if (d[0]) d[0]->block<1, 3>(0, 3) = -J;
    if (d[1]) d[1]->block<1, 3>(0, 3) = J;
    return e;
  }

 private:
  double yaw_meas_;
};

}  // namespace dlslot::backend
