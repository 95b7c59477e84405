// When within its sweep a spinning lidar fired at a point, and where a moving box was then.
//
// A scan that is not de-skewed (KITTI's raw and tracking scans, the simulator's by default) holds
// each point in the lidar frame of its own firing instant, the column fired at azimuth a at
// t(a) = -a / 2 pi x period (clockwise from behind: t = -period/2 behind, 0 ahead, +period/2 behind
// again), while the scan's pose, its labels and its detections are for t = 0, the instant it faces
// ahead (KITTI triggers its cameras then). A static point is where the pose puts it give or take
// the ego's motion, which the map and its truth share; a moving object's points are not in its
// box at t = 0 but in that box moved by the object's velocity relative to the lidar x t(a): up to
// half a sweep of the closing speed (50 m/s on a highway's other carriageway: 2.5 m behind the
// ego, 1.25 m beside it). Removing or labelling an object's points with its t = 0 box misses the
// object's trailing points and takes the static structure beside it.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "dlslot/types.hpp"

namespace dlslot {

struct SweepTiming {
  double period_s = 0.1;  // 0: every point at t = 0 (a de-skewed scan)
  bool clockwise = true;  // the firing order seen from above

  // Seconds from the reference instant (facing ahead) to the firing of a point at lidar-frame (x, y).
  double firingTime(double x, double y) const {
    if (period_s <= 0) return 0.0;
    const double a = azimuth(x, y);  // [-pi, pi], 0 ahead, positive to the left
    return (clockwise ? -a : a) / (2.0 * M_PI) * period_s;
  }
  // atan2(y, x) within 2.1e-4 rad (3 microseconds of a 0.1 s sweep: 0.2 mm at 50 m/s) at a fraction of its
  // cost: every point near a moving box asks for it (a minimax polynomial on [0, 1], folded).
  static double azimuth(double x, double y) {
    const double ax = std::abs(x), ay = std::abs(y), hi = std::max(ax, ay);
    if (hi == 0) return 0.0;
    const double a = std::min(ax, ay) / hi, s = a * a;
    double r = ((-0.0464964749 * s + 0.15931422) * s - 0.327622764) * s * a + a;
    if (ay > ax) r = M_PI / 2 - r;
    if (x < 0) r = M_PI - r;
    return y < 0 ? -r : r;
  }
  double maxOffset() const { return 0.5 * period_s; }
};

// A box (lidar frame) with its motion relative to the lidar: velocity of its centre (m/s) and rate
// of its yaw (rad/s), both as seen in the lidar frame (so the ego's own motion is in them).
struct MovingBox {
  Box box;
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  double yaw_rate = 0.0;

  // The box at t seconds from the reference instant (constant velocity over a sweep).
  Box at(double t) const {
    Box b = box;
    b.center += t * velocity;
    b.yaw += t * yaw_rate;
    return b;
  }
};

// The relative motion of a box seen in two scans' lidar frames dt apart (before, after): the yaw
// difference is taken modulo a half turn, since a detector's or label's heading may flip.
inline MovingBox movingBox(const Box& at_ref, const Box& before, const Box& after, double dt) {
  MovingBox m{at_ref, Eigen::Vector3d::Zero(), 0.0};
  if (!(dt > 0)) return m;
  m.velocity = (after.center - before.center) / dt;
  double dyaw = wrapAngle(after.yaw - before.yaw);
  if (std::abs(dyaw) > M_PI / 2) dyaw = wrapAngle(dyaw + M_PI);
  m.yaw_rate = dyaw / dt;
  return m;
}

}  // namespace dlslot
