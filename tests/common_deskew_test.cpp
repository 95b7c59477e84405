// De-skewing with known answers: the twist between two poses round-trips through its exponential,
// and a static scene scanned by a spinning lidar on a moving, turning vehicle (each point in the
// lidar frame of its own firing, as the simulator and KITTI's raw scans give them) lands back on
// the scene once de-skewed with the twist estimated from the neighbouring scans' poses.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "dlslot/deskew.hpp"
#include "sweep_scene.hpp"

using namespace dlslot;
using namespace dlslot::test;

TEST(Deskew, TheTwistBetweenTwoPosesRoundTripsThroughItsExponential) {
  for (const BodyTwist& w : {twist(12.0, 0.3, 0.4, 0.05), twist(-3.0, 0.0, -1.2), twist(0.0, 0.0, 0.0)}) {
    const double dt = 0.2;
    const BodyTwist back = twistBetween(lidarStart(), lidarStart() * w.at(dt), dt);
    EXPECT_NEAR((back.velocity - w.velocity).norm(), 0.0, 1e-9);
    EXPECT_NEAR((back.angular - w.angular).norm(), 0.0, 1e-9);
  }
  // A turn at constant twist is an arc: after a quarter turn at 10 m/s and 1 rad/s the lidar is
  // 10 m ahead and 10 m to the left, facing left.
  const Pose T = twist(10.0, 0.0, 1.0).at(M_PI / 2);
  EXPECT_NEAR(T.translation().x(), 10.0, 1e-9);
  EXPECT_NEAR(T.translation().y(), 10.0, 1e-9);
  EXPECT_NEAR(yawOf(T.linear()), M_PI / 2, 1e-9);
  // No time, no motion.
  EXPECT_TRUE(twistBetween(lidarStart(), lidarStart() * T, 0.0).velocity.isZero());
}

TEST(Deskew, AStaticSceneScannedFromAMovingTurningLidarLandsOnTheScene) {
  const SweepTiming sweep{0.1, true};
  const double radius = 20.0;
  const Pose T0 = lidarStart();
  // 15 m/s with a slight drift sideways, turning at 0.5 rad/s and pitching a little.
  const BodyTwist motion = twist(15.0, 0.5, 0.5, 0.02);
  PointCloud scan = skewedScanOfCylinder(T0, motion, sweep, radius);
  // As fired, the wall behind is split by the sweep's 1.5 m of travel and bent by its 2.9 deg of turn.
  const double skewed = worstOffWall(scan, T0, radius);
  EXPECT_GT(skewed, 0.5);
  // The mapper's estimate: the twist between the SLOT poses of the scans before and after.
  const BodyTwist estimated = twistBetween(T0 * motion.at(-0.1), T0 * motion.at(0.1), 0.2);
  deskew(scan, sweep, estimated);
  // The firing time is binned to 1/1024 of a sweep: within 0.05 ms, 1 mm here.
  EXPECT_LT(worstOffWall(scan, T0, radius), 0.003) << "as fired: " << skewed << " m off the wall";
}

TEST(Deskew, ThePointsOfADeskewedScanOrAStillLidarStayWhereTheyAre) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-30.0f, 30.0f);
  PointCloud scan(4, 500);
  for (Eigen::Index i = 0; i < scan.cols(); ++i) scan.col(i) << u(rng), u(rng), u(rng) / 10, 0.3f;
  const PointCloud before = scan;
  deskew(scan, SweepTiming{0.0, true}, twist(15.0, 0.0, 0.5));  // period 0: already de-skewed
  EXPECT_EQ((scan - before).cwiseAbs().maxCoeff(), 0.0f);
  deskew(scan, SweepTiming{0.1, true}, BodyTwist{});  // a still lidar
  EXPECT_LT((scan - before).cwiseAbs().maxCoeff(), 1e-6f);
  // Moving straight ahead at 10 m/s: a point straight behind (fired at the sweep's start or end:
  // on the seam) moves by 0.5 m along x, one ahead (t = 0) not at all, one to the left
  // (t = -0.025 s) 0.25 m back.
  PointCloud three(4, 3);
  three.col(0) << 10.0f, 0.0f, 0.0f, 0.0f;
  three.col(1) << 0.0f, 10.0f, 0.0f, 0.0f;
  three.col(2) << -10.0f, -1e-3f, 0.0f, 0.0f;  // just right of behind: fired last, t = +0.05 s
  deskew(three, SweepTiming{0.1, true}, twist(10.0, 0.0, 0.0));
  EXPECT_NEAR(three(0, 0), 10.0f, 1e-4f);
  EXPECT_NEAR(three(0, 1), -0.25f, 1e-3f);
  EXPECT_NEAR(three(0, 2), -9.5f, 1e-3f);
}
