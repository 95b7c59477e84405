// The odometry's guess while it cannot register (fallback frames), and its way back.
//
// A fallback publishes the constant-velocity prediction. Kept up for long, a stale velocity runs
// the guess away without bound (a vehicle that stopped while its scans were lost "drives on"
// for metres), and the jump guard then rejects every correct registration once scans return. So
// the velocity is kept whole for a few frames only (a scan or two lost while driving), then the
// guess brakes at a constant, moderate deceleration to a stop: it goes at most v^2 / (2 a) further
// (a crawling vehicle stays put; one at highway speed, which cannot stop in a second or two, keeps
// most of its speed). When scans return, scan-to-scan starts from both that guess and the old
// velocity kept up, and a registration is taken again when scan-to-map agrees with scan-to-scan
// (the motion from the last registered scan), however far it is from the published guess.
#pragma once

#include <Eigen/Geometry>

#include "dlslot/types.hpp"

namespace dlslot::odometry {

// Consecutive fallback frames that keep the last velocity whole.
constexpr int kFallbackHoldFrames = 3;
// Beyond them the guess slows down by this much per frame, m/frame per frame: 5 m/s^2 at
// KITTI's 10 Hz (firm braking; a car brakes at up to about 8).
constexpr double kFallbackBrakingM = 0.05;

// The rigid motion T scaled by f: its rotation angle and translation times f (exact for straight
// driving, close for the small turns of a frame or a few).
inline Pose scaledMotion(const Pose& T, double f) {
  const Eigen::AngleAxisd aa(T.linear());
  Pose out = Pose::Identity();
  out.linear() = Eigen::AngleAxisd(f * aa.angle(), aa.axis()).toRotationMatrix();
  out.translation() = f * T.translation();
  return out;
}

// `step` n times in a row: the motion over n frames at constant velocity.
inline Pose steps(const Pose& step, int n) {
  Pose T = Pose::Identity();
  for (int i = 0; i < n; ++i) T = T * step;
  return T;
}

// The velocity for the frame after the `fallbacks`-th consecutive fallback frame.
inline Pose fallbackVelocity(const Pose& velocity, int fallbacks) {
  if (fallbacks < kFallbackHoldFrames) return velocity;
  const double v = velocity.translation().norm();
  return v <= kFallbackBrakingM ? Pose::Identity() : scaledMotion(velocity, (v - kFallbackBrakingM) / v);
}

}  // namespace dlslot::odometry
