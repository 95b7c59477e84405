// A static scene scanned by a spinning lidar on a moving vehicle, each point in the lidar frame
// of its own firing (as the simulator and KITTI's raw scans give them): known answers for
// de-skewing.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "dlslot/deskew.hpp"

namespace dlslot::test {

// The lidar's velocity (x, y) and yaw and pitch rates, in its own frame.
inline BodyTwist twist(double vx, double vy, double yaw_rate, double pitch_rate = 0.0) {
  BodyTwist w;
  w.velocity = {vx, vy, 0.0};
  w.angular = {0.0, pitch_rate, yaw_rate};
  return w;
}

// Where the lidar is at the scan's reference instant.
inline Pose lidarStart() {
  Pose T = Pose::Identity();
  T.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(1.0, -2.0, 1.7);
  return T;
}

// A scan of a vertical cylinder wall of radius `radius` about the world's z axis, from a lidar at
// T_world_lidar(t) = T0 x motion.at(t): the column at azimuth a fires at t(a) (clockwise from
// behind over one sweep), each point in the lidar frame of its firing.
inline PointCloud skewedScanOfCylinder(const Pose& T0, const BodyTwist& motion, const SweepTiming& sweep, double radius) {
  const int columns = 2000;
  const int rows = 8;
  PointCloud out(4, columns * rows);
  for (int c = 0; c < columns; ++c) {
    const double t = (c + 0.5) / columns * sweep.period_s - 0.5 * sweep.period_s;
    const double a = -2.0 * M_PI * t / sweep.period_s;  // t(a) = -a / 2 pi x period
    const Pose T = T0 * motion.at(t);
    for (int r = 0; r < rows; ++r) {
      const double e = (-15.0 + 3.0 * r) * M_PI / 180.0;
      const Eigen::Vector3d d(std::cos(a) * std::cos(e), std::sin(a) * std::cos(e), std::sin(e));
      const Eigen::Vector3d o = T.translation(), dw = T.linear() * d;
      // |o_xy + s dw_xy| = radius, the positive root.
      const double A = dw.head<2>().squaredNorm(), B = 2 * o.head<2>().dot(dw.head<2>()),
                   C = o.head<2>().squaredNorm() - radius * radius;
      const double s = (-B + std::sqrt(B * B - 4 * A * C)) / (2 * A);
      out.col(c * rows + r) << (s * d).cast<float>(), 0.5f;
    }
  }
  return out;
}

// Largest distance of the scan's points (placed with T_world_lidar at the reference instant) from
// the wall.
inline double worstOffWall(const PointCloud& scan, const Pose& T0, double radius) {
  double worst = 0;
  for (Eigen::Index i = 0; i < scan.cols(); ++i) {
    const Eigen::Vector3d p = T0 * scan.col(i).head<3>().cast<double>();
    worst = std::max(worst, std::abs(p.head<2>().norm() - radius));
  }
  return worst;
}

}  // namespace dlslot::test
