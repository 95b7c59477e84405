// De-skewing with known answers: the twist between two poses round-trips through its exponential,
// and a static scene scanned by a spinning lidar on a moving, turning vehicle (each point in the
// lidar frame of its own firing, as the simulator and KITTI's raw scans give them) lands back on
// the scene once de-skewed with the twist estimated from the neighbouring scans' poses.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "dlslot/deskew.hpp"

using namespace dlslot;

namespace {

BodyTwist twist(double vx, double vy, double yaw_rate, double pitch_rate = 0.0) {
  BodyTwist w;
  w.velocity = {vx, vy, 0.0};
  w.angular = {0.0, pitch_rate, yaw_rate};
  return w;
}

Pose start() {
  Pose T = Pose::Identity();
  T.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(1.0, -2.0, 1.7);
  return T;
}

// A scan of a vertical cylinder wall of radius `radius` about the world's z axis, from a lidar at
// T_world_lidar(t) = T0 x motion.at(t): the column at azimuth a fires at t(a) (clockwise from
// behind over one sweep), each point in the lidar frame of its firing.
PointCloud skewedScanOfCylinder(const Pose& T0, const BodyTwist& motion, const SweepTiming& sweep, double radius) {
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
double worstOffWall(const PointCloud& scan, const Pose& T0, double radius) {
  double worst = 0;
  for (Eigen::Index i = 0; i < scan.cols(); ++i) {
    const Eigen::Vector3d p = T0 * scan.col(i).head<3>().cast<double>();
    worst = std::max(worst, std::abs(p.head<2>().norm() - radius));
  }
  return worst;
}

}  // namespace

TEST(Deskew, TheTwistBetweenTwoPosesRoundTripsThroughItsExponential) {
  for (const BodyTwist& w : {twist(12.0, 0.3, 0.4, 0.05), twist(-3.0, 0.0, -1.2), twist(0.0, 0.0, 0.0)}) {
    const double dt = 0.2;
    const BodyTwist back = twistBetween(start(), start() * w.at(dt), dt);
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
  EXPECT_TRUE(twistBetween(start(), start() * T, 0.0).velocity.isZero());
}

TEST(Deskew, AStaticSceneScannedFromAMovingTurningLidarLandsOnTheScene) {
  const SweepTiming sweep{0.1, true};
  const double radius = 20.0;
  const Pose T0 = start();
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
