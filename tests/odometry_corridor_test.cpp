// A degenerate corridor: two long parallel walls, the ground, guard-rail posts every 12 m, and a
// car driving with the ego (detected, as A-LOAM* removes it). Walls and ground fix the lateral and
// vertical position and the rotation; along the corridor only the posts say where the vehicle
// is. The vehicle stands for four scans (the odometry's velocity: zero), then drives at 2 m per
// scan: the map registration from the constant-velocity prediction finds the posts 2 m from
// where it looks (its neighbour search reaches 1 m) and, along the corridor, keeps the wrong
// (zero) velocity; a map built with it agrees with it. The periodic velocity check (scan-to-scan
// from the prediction, then from motion hypotheses when that one does not settle) must catch it
// within 10 frames, re-anchor the velocity and say so.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>

#include "odometry/lidar_odometry.hpp"
#include "odometry_scene.hpp"

namespace dlslot::odometry {
namespace {

constexpr double kStep = 2.0;  // m per scan once driving (20 m/s at 10 Hz)
constexpr int kStart = 4;      // the first scan taken after the vehicle moved

double trueX(int frame) { return frame < kStart ? 0.0 : kStep * (frame - kStart + 1); }

test::Scene corridor(double car_x) {
  test::Scene s;
  s.ground_z = -1.73;
  s.rects.push_back(test::wall({-150, 7.0}, {250, 7.0}, -1.73, 1.5));
  s.rects.push_back(test::wall({-150, -7.0}, {250, -7.0}, -1.73, 1.5));
  for (double x = -80; x <= 140; x += 12) {
    s.add(test::pillar({x, 6.0}, 0.1, -1.73, 0.0));
    s.add(test::pillar({x + 6, -6.0}, 0.1, -1.73, 0.0));
  }
  // The car 12 m ahead in the next lane, at the ego's speed: 4.4 x 1.8 x 1.5 m.
  const Eigen::Vector2d c(car_x + 12.0, -3.5);
  s.rects.push_back(test::wall(c + Eigen::Vector2d(-2.2, -0.9), c + Eigen::Vector2d(2.2, -0.9), -1.73, -0.23));
  s.rects.push_back(test::wall(c + Eigen::Vector2d(2.2, -0.9), c + Eigen::Vector2d(2.2, 0.9), -1.73, -0.23));
  s.rects.push_back(test::wall(c + Eigen::Vector2d(2.2, 0.9), c + Eigen::Vector2d(-2.2, 0.9), -1.73, -0.23));
  s.rects.push_back(test::wall(c + Eigen::Vector2d(-2.2, 0.9), c + Eigen::Vector2d(-2.2, -0.9), -1.73, -0.23));
  return s;
}

Frame scanAt(int frame) {
  const double x = trueX(frame);
  Frame f = test::frameOf(frame, corridor(x).scan(test::planarPose(x, 0, 0), 1200));
  Box car;
  car.center = Eigen::Vector3d(12.0, -3.5, -0.98);
  car.size = Eigen::Vector3d(4.4, 1.8, 1.5);
  car.type = "Car";
  f.detections = {car};
  return f;
}

constexpr int kFrames = kStart + 12;

TEST(OdometryCorridor, WrongVelocityIsCheckedAndReanchoredWithinTenFrames) {
  LidarOdometry odometry;  // the shipped defaults
  ASSERT_GT(odometry.config().check_every_frames, 0);
  ASSERT_LE(odometry.config().check_every_frames, 10);
  int first_reanchor = -1;
  std::vector<double> step_errors;  // of the motion since the previous scan
  for (int i = 0; i < kFrames; ++i) {
    const OdometryResult r = odometry.process(scanAt(i));
    step_errors.push_back(i == 0 ? 0.0 : std::abs(r.delta.translation().x() - (trueX(i) - trueX(i - 1))));
    if (std::getenv("DLSLOT_ODOM_TRACE"))
      std::fprintf(stderr, "frame %d x %.3f true %.3f checked %d hypotheses %d degeneracy %d: %s\n", i,
                   r.T_world_lidar.translation().x(), trueX(i), r.velocity_checked, r.motion_hypotheses,
                   static_cast<int>(r.degeneracy), r.status_text.c_str());
    EXPECT_TRUE(r.T_world_lidar.matrix().allFinite());
    // Standing still, the checks agree: nothing is re-anchored.
    if (i < kStart) {
      EXPECT_NE(r.degeneracy, Degeneracy::Reanchored) << "frame " << i << ": " << r.status_text;
    }
    if (r.degeneracy == Degeneracy::Reanchored && first_reanchor < 0) {
      first_reanchor = i;
      // Said in the result: checked, along the corridor (x), by how much, and why.
      EXPECT_TRUE(r.velocity_checked);
      EXPECT_GT(std::abs(r.weak_direction.x()), 0.9) << r.status_text;
      EXPECT_GT(std::abs(r.check_disagreement_m), 1.0);
      EXPECT_GT(r.check_chi2, odometry.config().check_chi2);
      EXPECT_NE(r.status_text.find("velocity re-anchored"), std::string::npos) << r.status_text;
    }
  }
  ASSERT_GE(first_reanchor, kStart) << "the wrong velocity was never re-anchored";
  EXPECT_LE(first_reanchor, kStart + 10);  // within 10 frames of the velocity going wrong
  // Before it the motion along the corridor was lost (the degenerate scene is what is tested)...
  EXPECT_GT(step_errors[kStart], 1.0);
  // ...from the re-anchoring on it is right again and stays so (the distance lost before is
  // not made up: scan-to-scan measures this scan's motion only).
  for (int i = first_reanchor; i < kFrames; ++i) EXPECT_LT(step_errors[i], 0.15) << "frame " << i;
}

// The same drive with the checks turned off: the map registration alone keeps the wrong (zero)
// velocity along the corridor. The scene is degenerate; the check is what recovers.
TEST(OdometryCorridor, WithoutTheCheckTheVelocityStaysWrong) {
  OdometryConfig cfg;
  cfg.weak_direction_ratio = 0.0;
  cfg.check_every_frames = 0;
  LidarOdometry odometry(cfg);
  double last_error = 0.0;
  for (int i = 0; i < kStart + 3; ++i) {
    const OdometryResult r = odometry.process(scanAt(i));
    EXPECT_EQ(r.degeneracy, Degeneracy::None);
    EXPECT_FALSE(r.velocity_checked);
    last_error = std::abs(r.T_world_lidar.translation().x() - trueX(i));
  }
  EXPECT_GT(last_error, 5.0);
}

}  // namespace
}  // namespace dlslot::odometry
