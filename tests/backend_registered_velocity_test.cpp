// A young vehicle's velocity from its registrations (procs/backend/registered_velocity.hpp):
// known motions with known information, partial measurements, the ego's error and the gate.
#include <gtest/gtest.h>

#include "backend/registered_velocity.hpp"

namespace dlslot::backend {
namespace {

// Information of a registration at the world tangent of M (translation, rotation): x, y and yaw
// measured to sigma_xy and sigma_yaw about the object's centre c (world), nothing else.
Matrix6 planarInformation(const Eigen::Vector3d& c, double sigma_x, double sigma_y, double sigma_yaw, const Pose& M) {
  Matrix6 centred = Matrix6::Zero();
  if (sigma_x > 0) centred(0, 0) = 1.0 / (sigma_x * sigma_x);
  if (sigma_y > 0) centred(1, 1) = 1.0 / (sigma_y * sigma_y);
  centred(5, 5) = 1.0 / (sigma_yaw * sigma_yaw);
  // Centred tangent -> world tangent at M, as the registration does (dt_c = dt_w - [R c]x dtheta).
  Matrix6 G = Matrix6::Identity();
  G.block<3, 3>(0, 3) = -skew(M.linear() * c);
  return G.transpose() * centred * G;
}

Pose planarMotion(double dx, double dy, double dyaw, const Eigen::Vector3d& about) {
  Pose R = Pose::Identity();
  R.linear() = Eigen::AngleAxisd(dyaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  Pose M = Pose::Identity();
  M.translation() = Eigen::Vector3d(dx, dy, 0) + about - R.linear() * about;  // turn about `about`, then move
  M.linear() = R.linear();
  return M;
}

TEST(RegisteredVelocity, CentreDisplacementOverTimeWithEgoError) {
  // A car 40 m from the world origin moves 1.5 m along x and 0.1 m along y while turning 0.02 rad.
  const Eigen::Vector3d c(40.0, -12.0, 0.8);
  const Pose M = planarMotion(1.5, 0.1, 0.02, c);
  const auto v = registeredVelocity(M, planarInformation(c, 0.01, 0.02, 0.002, M), c, 0.1, 0.02);
  ASSERT_TRUE(v.has_value());
  EXPECT_NEAR(v->velocity.x(), 15.0, 1e-9);
  EXPECT_NEAR(v->velocity.y(), 1.0, 1e-9);
  // Per axis the registration's variance plus the ego's, over dt^2: (0.01^2 + 0.02^2) / 0.01.
  EXPECT_NEAR(v->information(0, 0), 0.01 / (0.01 * 0.01 + 0.02 * 0.02), 1e-6 * v->information(0, 0));
  EXPECT_NEAR(v->information(1, 1), 0.01 / (0.02 * 0.02 + 0.02 * 0.02), 1e-6 * v->information(1, 1));
  EXPECT_NEAR(v->information(0, 1), 0.0, 1e-6 * v->information(0, 0));
}

TEST(RegisteredVelocity, UnmeasuredDirectionCarriesNoInformation) {
  const Eigen::Vector3d c(10.0, 5.0, 0.8);
  const Pose M = planarMotion(0.0, 1.0, 0.0, c);
  // Only y measured (a car seen from the side: along x nothing).
  const auto v = registeredVelocity(M, planarInformation(c, 0.0, 0.01, 0.002, M), c, 0.1, 0.0);
  ASSERT_TRUE(v.has_value());
  EXPECT_NEAR(v->information(1, 1), 0.01 / (0.01 * 0.01), 1e-3);
  EXPECT_NEAR(v->information(0, 0), 0.0, 1e-6);
  // Nothing measured horizontally, or no time: nothing.
  EXPECT_FALSE(registeredVelocity(M, planarInformation(c, 0.0, 0.0, 0.002, M), c, 0.1, 0.0).has_value());
  EXPECT_FALSE(registeredVelocity(M, planarInformation(c, 0.01, 0.01, 0.002, M), c, 0.0, 0.0).has_value());
}

TEST(RegisteredVelocity, FusionWeighsByInformationAndGatesOutliers) {
  // A line through 3 boxes: 10 m/s along x, 1 m/s standard deviation each axis.
  const Eigen::Vector2d line(10.0, 0.0);
  const Eigen::Matrix2d line_cov = Eigen::Matrix2d::Identity();
  // Two full registrations at 9.0 m/s, 0.2 m/s each: information 25 per axis each.
  VelocityEvidence r;
  r.velocity = Eigen::Vector2d(9.0, 0.0);
  r.information = 25.0 * Eigen::Matrix2d::Identity();
  FusedVelocity f = fuseVelocities(line, line_cov, {r, r});
  EXPECT_EQ(f.used, 2);
  EXPECT_NEAR(f.velocity.x(), (1.0 * 10.0 + 50.0 * 9.0) / 51.0, 1e-12);
  EXPECT_NEAR(f.velocity.y(), 0.0, 1e-12);
  EXPECT_TRUE(f.covariance.isApprox(Eigen::Matrix2d::Identity() / 51.0, 1e-12));  // the summed information's inverse
  // A partial one (x only) leaves y to the line.
  VelocityEvidence p;
  p.velocity = Eigen::Vector2d(9.5, 3.0);
  p.information << 100.0, 0.0, 0.0, 0.0;
  f = fuseVelocities(line, line_cov, {p});
  EXPECT_EQ(f.used, 1);
  EXPECT_NEAR(f.velocity.x(), (10.0 + 100.0 * 9.5) / 101.0, 1e-12);
  EXPECT_NEAR(f.velocity.y(), 0.0, 1e-12);
  EXPECT_NEAR(f.covariance(1, 1), 1.0, 1e-12);  // y: the line's alone
  // One 5 m/s off (another object's points): beyond the 99 % gate, left out.
  VelocityEvidence bad = r;
  bad.velocity = Eigen::Vector2d(5.0, 0.0);
  f = fuseVelocities(line, line_cov, {r, bad});
  EXPECT_EQ(f.used, 1);
  EXPECT_NEAR(f.velocity.x(), (10.0 + 25.0 * 9.0) / 26.0, 1e-12);
}

// A still vehicle seen end-on: three registrations measure its speed along the line of sight (x)
// to 0.2 m/s each and say nothing across it, where their velocities are noise.
TEST(RegisteredVelocity, MotionCountsOnlyWhereMeasured) {
  const auto endOn = [](double vx, double vy) {
    VelocityEvidence e;
    e.velocity = Eigen::Vector2d(vx, vy);
    e.information(0, 0) = 1.0 / (0.2 * 0.2);
    e.information(1, 1) = 1e-9;  // not measured: a velocity of 1e4 m/s costs nothing
    return e;
  };
  // Creeping off at 1.3 m/s: 1.3 / (0.2 / sqrt 3) = 11 sigmas, and faster than 1 m/s.
  EXPECT_TRUE(measuredMotion({endOn(1.2, 40.0), endOn(1.3, -70.0), endOn(1.4, 5.0)}, 1.0, 3.0));
  // Still: the noise across the line of sight is no evidence of motion.
  EXPECT_FALSE(measuredMotion({endOn(0.05, 40.0), endOn(-0.1, -70.0), endOn(0.02, 900.0)}, 1.0, 3.0));
  // Slower than min_speed, or within min_sigmas of still (one registration: 1.1 m/s is 5.5 sigmas,
  // 0.5 is 2.5).
  EXPECT_FALSE(measuredMotion({endOn(0.9, 0.0), endOn(0.9, 0.0), endOn(0.9, 0.0)}, 1.0, 3.0));
  EXPECT_TRUE(measuredMotion({endOn(1.1, 0.0)}, 1.0, 3.0));
  EXPECT_FALSE(measuredMotion({endOn(1.1, 0.0)}, 1.0, 6.0));
  // Measured in both directions: motion along y counts as well.
  VelocityEvidence full;
  full.velocity = Eigen::Vector2d(0.0, -1.5);
  full.information = Eigen::Matrix2d::Identity() / (0.2 * 0.2);
  EXPECT_TRUE(measuredMotion({full}, 1.0, 3.0));
  EXPECT_FALSE(measuredMotion({}, 1.0, 3.0));
}

}  // namespace
}  // namespace dlslot::backend
