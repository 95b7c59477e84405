// After a stretch of fallback frames the odometry comes back: the guess stops running on with a
// stale velocity, and once scans return a registration that scan-to-map and scan-to-scan agree on
// is taken however far the guess drifted (the 1000-frame highway soak stayed in fallback for its
// last 497 frames), whether the vehicle stopped or drove on meanwhile. A single solution far from
// a good prediction is still rejected.
#include <gtest/gtest.h>

#include "odometry/fallback_motion.hpp"
#include "odometry/lidar_odometry.hpp"
#include "odometry_scene.hpp"

namespace dlslot::odometry {
namespace {

Frame frameOf(int index, PointCloud scan) {
  Frame f;
  f.index = index;
  f.scan = std::move(scan);
  return f;
}

TEST(OdometryFallbackRecovery, VelocityHeldForAFewFramesThenDecays) {
  const Pose v = test::planarPose(1.0, 0.2, 0.05);
  for (int n = 1; n < kFallbackHoldFrames; ++n) EXPECT_TRUE(fallbackVelocity(v, n).isApprox(v));
  const Pose d = fallbackVelocity(v, kFallbackHoldFrames);
  EXPECT_NEAR(d.translation().x(), kFallbackDecay * 1.0, 1e-12);
  EXPECT_NEAR(d.translation().y(), kFallbackDecay * 0.2, 1e-12);
  EXPECT_NEAR(Eigen::AngleAxisd(d.linear()).angle(), kFallbackDecay * 0.05, 1e-12);
  // scaledMotion(., 1/n) undoes n steps of a constant turn.
  const Pose arc = v * v * v * v;
  EXPECT_TRUE(scaledMotion(arc, 0.25).linear().isApprox(v.linear(), 1e-12));
}

// The vehicle drives 1 m a frame, loses its scans at frame 6, slows down and stops at x = 8 while
// they are away, and stands there when they come back at frame 24. The guess comes to rest about
// 2.3 m ahead of it, beyond the jump guard's 2 m: the way back is a re-anchoring.
TEST(OdometryFallbackRecovery, StopsDuringADropoutAndRecoversWhenScansReturn) {
  const test::Scene street = test::street();
  auto truthX = [](int i) { return i <= 6 ? i : i >= 9 ? 8.0 : i == 7 ? 7.5 : 7.9; };
  LidarOdometry odometry;
  int first_ok_after = -1;
  for (int i = 0; i < 30; ++i) {
    const Pose T = test::planarPose(truthX(i), 0.0, 0.0);
    const bool lost = i >= 6 && i < 24;
    const OdometryResult r = odometry.process(frameOf(i, lost ? PointCloud(4, 0) : street.scan(T)));
    if (lost) {
      EXPECT_EQ(r.status, Status::FallbackFewPoints) << "frame " << i;
      // The guess moves on for a few frames, then comes to rest instead of driving away.
      EXPECT_LT(r.T_world_lidar.translation().x(), 6.0 + kFallbackHoldFrames + 3.0) << "frame " << i;
      continue;
    }
    if (i < 24) {
      EXPECT_EQ(r.status, i == 0 ? Status::FirstFrame : Status::Ok) << "frame " << i << ": " << r.status_text;
      continue;
    }
    if (r.status == Status::Ok && first_ok_after < 0) {
      first_ok_after = i;
      EXPECT_NE(r.status_text.find("re-anchored"), std::string::npos) << r.status_text;
    }
    if (first_ok_after >= 0) {  // back for good, where the vehicle is
      EXPECT_EQ(r.status, Status::Ok) << "frame " << i << ": " << r.status_text;
      EXPECT_LT((r.T_world_lidar.translation() - T.translation()).norm(), 0.1) << "frame " << i;
      if (i > first_ok_after) {
        EXPECT_LT(r.delta.translation().norm(), 0.05) << "frame " << i << ": standing";
      }
    }
  }
  ASSERT_GE(first_ok_after, 24) << "never recovered";
  EXPECT_LE(first_ok_after, 26) << "recovered only at frame " << first_ok_after;
}

// The vehicle keeps driving 1.5 m a frame through 10 lost scans: the published guess has come to
// rest far behind it, and the scan-to-scan started from the old velocity kept up finds it again
// (a periodic street: started from the resting guess it would lock onto the wrong block).
TEST(OdometryFallbackRecovery, KeepsItsSpeedThroughADropoutAndRecovers) {
  const test::Scene street = test::street();
  LidarOdometry odometry;
  for (int i = 0; i < 19; ++i) {
    const Pose T = test::planarPose(1.5 * i, 0.0, 0.0);
    const bool lost = i >= 6 && i < 16;
    const OdometryResult r = odometry.process(frameOf(i, lost ? PointCloud(4, 0) : street.scan(T)));
    if (lost) continue;
    EXPECT_EQ(r.status, i == 0 ? Status::FirstFrame : Status::Ok) << "frame " << i << ": " << r.status_text;
    EXPECT_LT((r.T_world_lidar.translation() - T.translation()).norm(), 0.1) << "frame " << i;
    if (i == 16) {
      EXPECT_NE(r.status_text.find("re-anchored"), std::string::npos) << r.status_text;
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
    const OdometryResult r = odometry.process(frameOf(i, street.scan(test::planarPose(x, 0.0, 0.0))));
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
