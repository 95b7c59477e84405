// A scan pair's speed along the line of sight as a measurement on a vehicle's chain (not in the
// paper's graph). The face a vehicle shows the sensor (its front or back, line_of_sight.hpp) moves
// from one scan to the next by the vehicle's motion against the sensor; along the line of sight u
// a lidar measures that to centimetres, where the boxes give decimetres. With eq. 10 (o_t = o_{t-1} c)
// and the ego poses, the face's displacement against the sensor along u is
//   d = u . (R(o_{t-1}) t(c) - (t(X_t) - t(X_{t-1}))),
// on the blocks X_{t-1}, X_t, o_{t-1} and c, and e = d - d_meas. The measurement is taken against
// the sensor (the ego displacement the scan pair was put into the world with is taken out of it),
// for the reason the registration factor is (registration_factor.hpp): a world-frame measurement
// would bring the odometry's motion into the window once more for every such vehicle.
// The face's own turn (a yaw rate times its half length) is left out: the face is within 10 deg
// of head-on and a vehicle turning hard enough to matter shows its side.
// The same factor takes a side's ends' speed along the vehicle's heading (side_ends.hpp), u then
// the heading: the ends' middle is the body's centre along it, which a turn does not move.
#pragma once

#include "backend/pose_factor.hpp"

namespace dlslot::backend {

class SightSpeedFactor final : public PoseFactor {
 public:
  // u: the horizontal unit line of sight (world); d_meas: the face's displacement against the
  // sensor along u (m); sigma: its standard deviation (m).
  SightSpeedFactor(const Eigen::Vector3d& u, double d_meas, double sigma)
      : PoseFactor(4, scalarWhitening(sigma)), u_(u), d_meas_(d_meas) {}
  static ceres::CostFunction* Create(const Eigen::Vector3d& u, double d_meas, double sigma) {
    return new SightSpeedFactor(u, d_meas, sigma);
  }

 protected:
  // Parameters: X_{t-1}, X_t, o_{t-1}, c. Only e[0] is used; the other rows are zero.
  Vector6 error(double const* const* x, Matrix6* const* d) const override {
    const Pose X_prev = fromBlock(x[0]), X_cur = fromBlock(x[1]), o = fromBlock(x[2]), c = fromBlock(x[3]);
    const Eigen::Vector3d v = o.linear() * c.translation();
    Vector6 e = Vector6::Zero();
    e[0] = u_.dot(v - (X_cur.translation() - X_prev.translation())) - d_meas_;
    // Tangent perturbations (pose_manifold.hpp): translations add in the world, rotations are
    // Exp(dtheta) R, and u . (Exp(dtheta) v) moves by dtheta . (v x u).
    for (int k = 0; k < 4; ++k)
      if (d[k]) d[k]->setZero();
    if (d[0]) d[0]->block<1, 3>(0, 0) = u_.transpose();
    if (d[1]) d[1]->block<1, 3>(0, 0) = -u_.transpose();
    if (d[2]) d[2]->block<1, 3>(0, 3) = v.cross(u_).transpose();
    if (d[3]) {
      // c's translation moves one for one with its tangent's, in c's own (start) frame.
      d[3]->block<1, 3>(0, 0) = u_.transpose() * o.linear();
    }
    return e;
  }

 private:
  Eigen::Vector3d u_;
  double d_meas_;
};

}  // namespace dlslot::backend
