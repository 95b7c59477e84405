// The window's motion evidence (motion_evidence.hpp): the least-squares line through a track's
// positions and a vehicle's velocity turned toward its heading, against known answers.
#include <gtest/gtest.h>

#include <Eigen/LU>

#include <cmath>
#include <cstdio>
#include <random>

#include "backend/motion_evidence.hpp"

using namespace dlslot::backend;

TEST(BackendMotionEvidence, FitSpeedIsTheLeastSquaresLine) {
  // 10 m/s along x with +-0.1 m alternating noise over 5 samples 0.1 s apart.
  std::vector<TimedPosition> p;
  for (int k = 0; k < 5; ++k) p.push_back({0.1 * k, Eigen::Vector3d(1.0 * k + (k % 2 ? 0.1 : -0.1), 2.0, 0.0)});
  const auto fit = fitSpeed(p, 0.2);
  ASSERT_TRUE(fit);
  // Slope of y_k = k + e_k with e = (-.1, .1, -.1, .1, -.1): sum (t - 0.2) e / sum (t - 0.2)^2 = 0 / 0.1.
  EXPECT_NEAR(fit->velocity.x(), 10.0, 1e-9);
  EXPECT_NEAR(fit->velocity.y(), 0.0, 1e-12);
  EXPECT_NEAR(fit->sigma, 0.2 / std::sqrt(0.1), 1e-12);
  EXPECT_FALSE(fitSpeed({p[0]}, 0.2));
}

// highway-jam seed 3's oncoming van: its first box (0.5 s before the others, 3 m aside) was
// another object's. The least-squares line through all four says -3.2 m/s; a residual test after
// it would drop the wrong box (the line passes 0.6 m from the stray one, 1.9 m from a good one).
TEST(BackendMotionEvidence, FitAmongOutliersLeavesOutAnotherObjectsBox) {
  const std::vector<TimedPosition> p{{7.7, Eigen::Vector3d(141.84, 8.35, 0)},
                                     {8.2, Eigen::Vector3d(142.77, 5.38, 0)},
                                     {8.3, Eigen::Vector3d(140.98, 5.02, 0)},
                                     {8.4, Eigen::Vector3d(138.48, 5.47, 0)}};
  EXPECT_NEAR(fitSpeed(p, 0.3)->velocity.x(), -3.18, 0.01);
  const auto robust = fitSpeedAmongOutliers(p, 0.3, 5.0);
  ASSERT_TRUE(robust);
  const auto without = fitSpeed({p[1], p[2], p[3]}, 0.3);
  EXPECT_TRUE(robust->velocity.isApprox(without->velocity, 1e-12));  // the line through the last three
  EXPECT_NEAR(robust->velocity.x(), -21.45, 0.01);
  EXPECT_NEAR(robust->sigma, without->sigma, 1e-12);
  // Consistent positions keep every one: the plain least-squares line.
  std::vector<TimedPosition> line;
  for (int k = 0; k < 6; ++k) line.push_back({0.1 * k, Eigen::Vector3d(2.4 * k + (k % 2 ? 0.1 : -0.1), 0, 0)});
  EXPECT_TRUE(fitSpeedAmongOutliers(line, 0.2, 5.0)->velocity.isApprox(fitSpeed(line, 0.2)->velocity, 1e-12));
  // Three or fewer positions: no consensus to find, the plain line.
  EXPECT_TRUE(fitSpeedAmongOutliers({p[0], p[1], p[2]}, 0.3, 5.0)->velocity.isApprox(fitSpeed({p[0], p[1], p[2]}, 0.3)->velocity, 1e-12));
}

// highway-jam seed 2: two oncoming cars in adjacent lanes (3.5 m apart, -22 m/s) given one track
// by the tracker, two boxes each, 70 m away (sigma 0.36 m, gate 1.8 m). The consensus of pairs
// found a line through one box of each and a third within the gate: 10 m/s sideways, -4.4 m/s
// along the road once turned to the heading. A vehicle's pairs that moved across its heading by
// more than the gate are two objects: the line through one car's boxes.
TEST(BackendMotionEvidence, AVehiclesLineIsNotDrawnAcrossTwoLanes) {
  const std::vector<TimedPosition> p{{11.5, Eigen::Vector3d(155.72, 4.57, 0)},
                                     {11.6, Eigen::Vector3d(153.49, 4.65, 0)},
                                     {11.8, Eigen::Vector3d(155.61, 8.07, 0)},
                                     {11.9, Eigen::Vector3d(153.51, 8.42, 0)}};
  const auto sideways = fitSpeedAmongOutliers(p, 0.36, 5.0);
  ASSERT_TRUE(sideways);
  EXPECT_GT(std::abs(sideways->velocity.y()), 5.0);
  const Eigen::Vector2d heading(-1.0, 0.0);
  const auto along = fitSpeedAmongOutliers(p, 0.36, 5.0, &heading);
  ASSERT_TRUE(along);
  // Two boxes of each car: the newer car's, the one the track is now.
  EXPECT_NEAR(along->velocity.x(), -21.0, 0.05);
  EXPECT_LT(std::abs(along->velocity.y()), 4.0);
  // Three positions, one of them the other car's: outvoted with a heading, not without.
  const std::vector<TimedPosition> three{p[0], p[1], p[2]};
  EXPECT_NEAR(fitSpeedAmongOutliers(three, 0.36, 5.0, &heading)->velocity.x(), -22.3, 0.05);
  EXPECT_TRUE(fitSpeedAmongOutliers(three, 0.36, 5.0)->velocity.isApprox(fitSpeed(three, 0.36)->velocity, 1e-12));
  // Boxes that all move along the heading: every one kept, the plain line.
  std::vector<TimedPosition> lane;
  for (int k = 0; k < 6; ++k) lane.push_back({0.1 * k, Eigen::Vector3d(-2.2 * k, (k % 2 ? 0.2 : -0.2), 0)});
  EXPECT_TRUE(fitSpeedAmongOutliers(lane, 0.2, 5.0, &heading)->velocity.isApprox(fitSpeed(lane, 0.2)->velocity, 1e-12));
}

TEST(BackendMotionEvidence, VelocityAlongHeadingWeighsTheTwoEstimates) {
  SpeedFit fit;
  fit.velocity = Eigen::Vector3d(10.0, 1.0, 0.3);  // 1 m/s across a heading along x
  fit.sigma = 0.5;
  const Eigen::Vector2d x(1.0, 0.0);
  // Heading sigma 0.05 rad at |v| = 10.05 m/s: 0.5025 m/s, about as uncertain as the fit.
  const double var_h = std::pow(std::hypot(10.0, 1.0) * 0.05, 2), w = var_h / (var_h + 0.25);
  Eigen::Vector3d v = velocityAlongHeading(fit, x, 0.05);
  EXPECT_NEAR(v.x(), 10.0, 1e-12);
  EXPECT_NEAR(v.y(), w * 1.0, 1e-12);
  EXPECT_NEAR(v.y(), 0.5, 0.01);
  EXPECT_NEAR(v.z(), 0.3, 1e-12);  // height untouched
  // A sure heading removes the sideways part; a useless one keeps the fit.
  EXPECT_NEAR(velocityAlongHeading(fit, x, 1e-9).y(), 0.0, 1e-9);
  EXPECT_NEAR(velocityAlongHeading(fit, x, 1e3).y(), 1.0, 1e-6);
  // The heading's sign does not matter (a box and the box turned by pi are the same box).
  EXPECT_TRUE(velocityAlongHeading(fit, -x, 0.05).isApprox(v, 1e-12));
  // A heading at 90 deg to the motion is believed as much: the 10 m/s across it is halved.
  EXPECT_NEAR(velocityAlongHeading(fit, Eigen::Vector2d(0.0, 1.0), 0.05).x(), w * 10.0, 1e-9);
}

TEST(BackendMotionEvidence, OneAxisSigmasHaveThePlanesFalseAlarm) {
  for (double k : {1.0, 2.0, 3.0}) {
    const double k1 = sigmasOnOneAxis(k);
    EXPECT_NEAR(std::erfc(k1 / std::sqrt(2.0)), std::exp(-0.5 * k * k), 1e-12);
    EXPECT_LT(k1, k);
  }
  EXPECT_NEAR(sigmasOnOneAxis(2.0), 1.4934, 1e-4);  // 13.5 % of a still object's fits either way
  EXPECT_NEAR(sigmasOnOneAxis(0.0), 0.0, 1e-12);
}

// A line of sigma s per axis fused with a zero-mean prior of rms^2 / 2 per axis: the known answer
// (each axis shrunk by p / (p + s^2), variance 1 / (1 / s^2 + 1 / p)); and over walkers that walk
// at 1.2 m/s in random directions, measured with 1 m/s of noise, the estimate's error is smaller
// than the line's and its covariance says how large it is (mean NEES 2 for 2 dimensions).
TEST(BackendMotionEvidence, AWalkersSpeedPriorIsTheLinearLeastSquaresEstimate) {
  const double s = 1.0, rms = 1.2, p = rms * rms / 2;
  const PlanarVelocity v = withSpeedPrior(Eigen::Vector2d(1.5, -0.5), s * s * Eigen::Matrix2d::Identity(), rms);
  EXPECT_NEAR(v.velocity.x(), 1.5 * p / (p + s * s), 1e-12);
  EXPECT_NEAR(v.velocity.y(), -0.5 * p / (p + s * s), 1e-12);
  EXPECT_NEAR(v.covariance(0, 0), 1.0 / (1.0 / (s * s) + 1.0 / p), 1e-12);
  EXPECT_NEAR(v.covariance(0, 1), 0.0, 1e-12);
  // No prior, or a line far surer than the prior: (nearly) unchanged.
  EXPECT_EQ(withSpeedPrior(Eigen::Vector2d(1.5, -0.5), Eigen::Matrix2d::Identity(), 0.0).velocity, Eigen::Vector2d(1.5, -0.5));
  EXPECT_NEAR(withSpeedPrior(Eigen::Vector2d(1.5, 0), 1e-4 * Eigen::Matrix2d::Identity(), rms).velocity.x(), 1.5, 1e-3);

  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, s);
  std::uniform_real_distribution<double> direction(-M_PI, M_PI);
  double line_se = 0, prior_se = 0, nees = 0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const double a = direction(rng);
    const Eigen::Vector2d truth = rms * Eigen::Vector2d(std::cos(a), std::sin(a));
    const Eigen::Vector2d line = truth + Eigen::Vector2d(noise(rng), noise(rng));
    const PlanarVelocity e = withSpeedPrior(line, s * s * Eigen::Matrix2d::Identity(), rms);
    line_se += (line - truth).squaredNorm();
    prior_se += (e.velocity - truth).squaredNorm();
    nees += (e.velocity - truth).dot(e.covariance.inverse() * (e.velocity - truth));
  }
  std::printf("walkers at %.1f m/s, lines of %.1f m/s noise: RMS error %.3f -> %.3f m/s, mean NEES %.2f\n", rms, s,
              std::sqrt(line_se / n), std::sqrt(prior_se / n), nees / n);
  EXPECT_LT(prior_se, 0.6 * line_se);
  EXPECT_NEAR(nees / n, 2.0, 0.1);
}
