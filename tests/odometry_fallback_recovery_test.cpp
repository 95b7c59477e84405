// After a stretch of fallback frames the odometry comes back: the guess stops running on with a
// stale velocity, and once scans return a registration that scan-to-map and scan-to-scan agree on
// is taken however far the guess drifted (the 1000-frame highway soak stayed in fallback for its
// last 497 frames), whether the vehicle stopped or drove on meanwhile. A single solution far from
// a good prediction is still rejected.
#include <gtest/gtest.h>

#include <algorithm>

#include "odometry/fallback_motion.hpp"
#include "odometry/lidar_odometry.hpp"
#include "odometry_scene.hpp"

namespace dlslot::odometry {
namespace {

TEST(OdometryFallbackRecovery, VelocityHeldForAFewFramesThenBrakesToAStop) {
  const Pose v = test::planarPose(0.8, 0.6, 0.05);  // 1 m a frame, turning
  for (int n = 1; n < kFallbackHoldFrames; ++n) EXPECT_TRUE(fallbackVelocity(v, n).isApprox(v));
  const Pose d = fallbackVelocity(v, kFallbackHoldFrames);
  const double f = 1.0 - kFallbackBrakingM;  // the speed lost in a frame, turning on the same circle
  EXPECT_NEAR(d.translation().x(), f * 0.8, 1e-12);
  EXPECT_NEAR(d.translation().y(), f * 0.6, 1e-12);
  EXPECT_NEAR(Eigen::AngleAxisd(d.linear()).angle(), f * 0.05, 1e-12);
  // Braking ends standing, after at most v^2 / (2 a) (plus a frame) further.
  Pose u = v, T = Pose::Identity();
  int n = kFallbackHoldFrames;
  for (; n < 1000 && !u.isApprox(Pose::Identity()); ++n) {
    u = fallbackVelocity(u, n);
    T = T * u;
  }
  EXPECT_LT(n, kFallbackHoldFrames + 1.0 / kFallbackBrakingM + 1);
  EXPECT_LT(T.translation().norm(), 1.0 / (2 * kFallbackBrakingM) + 1.0);
  EXPECT_TRUE(fallbackVelocity(test::planarPose(0.01, 0, 0), kFallbackHoldFrames).isApprox(Pose::Identity()));
  // scaledMotion(., 1/n) undoes n steps of a constant turn.
  EXPECT_TRUE(scaledMotion(steps(v, 4), 0.25).linear().isApprox(v.linear(), 1e-12));
}

// The vehicle drives 1 m a frame (10 m/s), loses its scans at frame 6 as it brakes at 4 m/s^2
// from frame 5, stops at x = 17 while they are away and stands there when they come back at
// frame 30. The guess, held 3 frames, then braking, comes to rest within a metre of it. (Before,
// it drove on at 1 m a frame, 24 m past the vehicle, and never came back.)
TEST(OdometryFallbackRecovery, StopsDuringADropoutAndRecoversWhenScansReturn) {
  const test::Scene street = test::street();
  auto truthX = [](int i) {
    double x = std::min(i, 5);
    for (int k = 1; k <= i - 5; ++k) x += std::max(0.0, 1.0 - 0.04 * k);
    return x;
  };
  LidarOdometry odometry;
  int first_ok_after = -1;
  for (int i = 0; i < 36; ++i) {
    const Pose T = test::planarPose(truthX(i), 0.0, 0.0);
    const bool lost = i >= 6 && i < 30;
    const OdometryResult r = odometry.process(test::frameOf(i, lost ? PointCloud(4, 0) : street.scan(T)));
    if (lost) {
      EXPECT_EQ(r.status, Status::FallbackFewPoints) << "frame " << i;
      // The guess moves on for a few frames, then brakes to a stop instead of driving away.
      EXPECT_LT(r.T_world_lidar.translation().x(), 5.0 + kFallbackHoldFrames + 1.0 / (2 * kFallbackBrakingM) + 1.0)
          << "frame " << i;
      continue;
    }
    if (i < 30) {
      EXPECT_EQ(r.status, i == 0 ? Status::FirstFrame : Status::Ok) << "frame " << i << ": " << r.status_text;
      continue;
    }
    if (r.status == Status::Ok && first_ok_after < 0) {
      first_ok_after = i;
      EXPECT_NE(r.status_text.find("after 24 fallback frames"), std::string::npos) << r.status_text;
    }
    if (first_ok_after >= 0) {  // back for good, where the vehicle is
      EXPECT_EQ(r.status, Status::Ok) << "frame " << i << ": " << r.status_text;
      EXPECT_LT((r.T_world_lidar.translation() - T.translation()).norm(), 0.1) << "frame " << i;
      if (i > first_ok_after) {
        EXPECT_LT(r.delta.translation().norm(), 0.05) << "frame " << i << ": standing";
      }
    }
  }
  ASSERT_GE(first_ok_after, 30) << "never recovered";
  EXPECT_LE(first_ok_after, 32) << "recovered only at frame " << first_ok_after;
}

// The vehicle keeps driving 1.5 m a frame through 15 lost scans: the published guess, braking,
// falls 4 m behind, beyond the jump guard's 2 m; the scan-to-scan started from the old velocity
// kept up finds the vehicle again, and the odometry re-anchors there.
TEST(OdometryFallbackRecovery, KeepsItsSpeedThroughADropoutAndRecovers) {
  const test::Scene street = test::street();
  LidarOdometry odometry;
  for (int i = 0; i < 24; ++i) {
    const Pose T = test::planarPose(1.5 * i, 0.0, 0.0);
    const bool lost = i >= 6 && i < 21;
    const OdometryResult r = odometry.process(test::frameOf(i, lost ? PointCloud(4, 0) : street.scan(T)));
    if (lost) continue;
    EXPECT_EQ(r.status, i == 0 ? Status::FirstFrame : Status::Ok) << "frame " << i << ": " << r.status_text;
    EXPECT_LT((r.T_world_lidar.translation() - T.translation()).norm(), 0.1) << "frame " << i;
    if (i == 21) {
      EXPECT_NE(r.status_text.find("re-anchored after 15 fallback frames"), std::string::npos) << r.status_text;
    }
  }
}

// One scan far from a good prediction (as from a registration gone wrong) is kept out by the jump
// guard; the next good scan is taken as usual.
TEST(OdometryFallbackRecovery, SingleFarSolutionStillRejected) {
  const test::Scene street = test::street();
  OdometryConfig cfg;
  cfg.max_correction_m = 0.5;
  LidarOdometry odometry(cfg);
  for (int i = 0; i < 10; ++i) {
    const double x = i == 5 ? 5.8 : i;  // frame 5 seen 0.8 m from where the vehicle is
    const OdometryResult r = odometry.process(test::frameOf(i, street.scan(test::planarPose(x, 0.0, 0.0))));
    if (i == 5) {
      EXPECT_EQ(r.status, Status::FallbackSolveFailed) << r.status_text;
      EXPECT_NE(r.status_text.find("jumped"), std::string::npos) << r.status_text;
      EXPECT_NEAR(r.T_world_lidar.translation().x(), 5.0, 0.1);  // the prediction
    } else {
      EXPECT_EQ(r.status, i == 0 ? Status::FirstFrame : Status::Ok) << "frame " << i << ": " << r.status_text;
      EXPECT_NEAR(r.T_world_lidar.translation().x(), x, 0.1) << "frame " << i;
    }
  }
}

}  // namespace
}  // namespace dlslot::odometry
