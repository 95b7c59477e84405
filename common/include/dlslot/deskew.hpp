// De-skewing a scan: every point moved from the lidar frame of its own firing instant into the
// lidar frame of the scan's reference instant (sweep_timing.hpp), with the ego's motion over the
// sweep taken as constant (one twist, from the poses of the neighbouring scans).
//
// Why: a vehicle at 10 m/s moves 1 m during a 0.1 s sweep. The points behind it are fired at the
// two ends of the sweep (t = -period/2 and +period/2), so a static wall behind it appears split
// by +-0.5 m, and a turning vehicle's scan is bent by its yaw rate x half a sweep. Registering two
// skewed scans taken at different speeds (a loop's two sides: one slow, one fast) reads that
// shear as a rotation of the whole scan, tenths of a degree, which over a loop's tens of metres
// of lever is tenths of a metre.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <vector>

#include "dlslot/sweep_timing.hpp"
#include "dlslot/types.hpp"

namespace dlslot {

// A constant body twist: the lidar's velocity and angular velocity expressed in its own frame.
// For a constant twist the body-frame coordinates stay the same along the motion, so the twist
// estimated between two neighbouring scans holds in the frame of the scan between them.
struct BodyTwist {
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  // m/s
  Eigen::Vector3d angular = Eigen::Vector3d::Zero();   // rad/s

  // T_ref_lidar(t): the lidar at t seconds after the reference instant, in the reference frame
  // (the SE(3) exponential of t x the twist).
  Pose at(double t) const {
    const Eigen::Vector3d w = t * angular, v = t * velocity;
    const double th = w.norm();
    Eigen::Matrix3d K;
    K << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
    Eigen::Matrix3d V = Eigen::Matrix3d::Identity();
    Pose T = Pose::Identity();
    if (th > 1e-9) {
      T.linear() = Eigen::AngleAxisd(th, w / th).toRotationMatrix();
      V += (1 - std::cos(th)) / (th * th) * K + (th - std::sin(th)) / (th * th * th) * K * K;
    } else {
      T.linear() += K;
      V += 0.5 * K;
    }
    T.translation() = V * v;
    return T;
  }
};

// The twist that takes T_world_lidar `from` to `to` in dt seconds (the SE(3) logarithm / dt);
// zero when dt is not positive.
inline BodyTwist twistBetween(const Pose& from, const Pose& to, double dt) {
  BodyTwist out;
  if (!(dt > 0)) return out;
  const Pose D = from.inverse() * to;
  const Eigen::AngleAxisd aa(D.linear());
  const double th = aa.angle();
  const Eigen::Vector3d w = th * aa.axis();
  Eigen::Matrix3d K;
  K << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
  Eigen::Matrix3d Vinv = Eigen::Matrix3d::Identity() - 0.5 * K;
  if (th > 1e-6) Vinv += (1.0 / (th * th) - (1 + std::cos(th)) / (2 * th * std::sin(th))) * K * K;
  else Vinv += K * K / 12.0;
  out.angular = w / dt;
  out.velocity = Vinv * D.translation() / dt;
  return out;
}

// The motion of one sweep, for moving points (lidar frame of their firing) into the lidar frame
// of the reference instant: p_ref = T_ref_lidar(t(p)) p. The firing time is quantized to 1/1024
// of the sweep (98 microseconds of a 0.1 s sweep: 2 mm at 20 m/s), one transform per bin, so a
// scan of 100k points costs 100k small matrix products. A period of 0 (de-skewed scans) leaves
// the points where they are.
class SweepMotion {
 public:
  SweepMotion(const SweepTiming& sweep, const BodyTwist& twist) : sweep_(sweep) {
    if (sweep_.period_s <= 0) return;
    R_.resize(kBins + 1);
    t_.resize(kBins + 1);
    for (int b = 0; b <= kBins; ++b) {
      const Pose T = twist.at((static_cast<double>(b) / kBins - 0.5) * sweep_.period_s);
      R_[b] = T.linear().cast<float>();
      t_[b] = T.translation().cast<float>();
    }
  }

  Eigen::Vector3f toReference(const Eigen::Vector3f& p) const {
    if (R_.empty()) return p;
    const double f = sweep_.firingTime(p.x(), p.y()) / sweep_.period_s + 0.5;  // [0, 1]
    const int b = std::clamp(static_cast<int>(std::lround(f * kBins)), 0, kBins);
    return R_[b] * p + t_[b];
  }

 private:
  static constexpr int kBins = 1024;
  SweepTiming sweep_;
  std::vector<Eigen::Matrix3f> R_;
  std::vector<Eigen::Vector3f> t_;
};

// Every point of `points` (x y z in rows 0-2) into the lidar frame of the reference instant.
inline void deskew(PointCloud& points, const SweepTiming& sweep, const BodyTwist& twist) {
  if (sweep.period_s <= 0) return;
  const SweepMotion motion(sweep, twist);
  for (Eigen::Index i = 0; i < points.cols(); ++i) points.col(i).head<3>() = motion.toReference(points.col(i).head<3>());
}

}  // namespace dlslot
