// The trajectory polynomial (eq. 3-5): exact on polynomial motion, well conditioned on real
// timestamps, lower degree for short histories, and the window displacement.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>

#include "trajectory_predictor.hpp"

using namespace dlslot::tracker;

namespace {

std::vector<TrajectoryPoint> sample(const std::function<Eigen::Vector2d(double)>& f, int n, double t0, double dt) {
  std::vector<TrajectoryPoint> pts;
  for (int i = 0; i < n; ++i) {
    const double t = t0 + i * dt;
    const Eigen::Vector2d p = f(t - t0);
    pts.push_back({i, t, Eigen::Vector3d(p.x(), p.y(), -0.8)});
  }
  return pts;
}

}  // namespace

TEST(TrackerPredictor, DegreeFollowsHistoryAndHorizon) {
  // Equally spaced observations, predicted h frames after the last: the highest degree whose
  // noise gain stays <= 3. A cubic needs 7 observations one frame ahead; across two missed
  // frames even 10 observations only support a quadratic, with less history a line.
  const int one_ahead[] = {0, 1, 1, 2, 2, 2, 3, 3, 3, 3};
  const int three_ahead[] = {0, 1, 1, 1, 1, 1, 1, 1, 2, 2};
  for (int n = 1; n <= 10; ++n) {
    std::vector<TrajectoryPoint> pts;
    for (int i = 0; i < n; ++i) pts.push_back({i, 0.1 * i, Eigen::Vector3d::Zero()});
    const Prediction p1 = predictPolynomial(pts, 0.1 * n), p3 = predictPolynomial(pts, 0.1 * (n + 2));
    EXPECT_EQ(p1.degree, one_ahead[n - 1]) << n;
    EXPECT_EQ(p3.degree, three_ahead[n - 1]) << n;
    if (n >= 2) {
      EXPECT_LE(p1.noise_gain, 3.0) << n;
    }
  }
  // The known gain of the 10-point cubic one step ahead, and the cap on the degree.
  std::vector<TrajectoryPoint> pts;
  for (int i = 0; i < 10; ++i) pts.push_back({i, 0.1 * i, Eigen::Vector3d::Zero()});
  EXPECT_NEAR(predictPolynomial(pts, 1.0).noise_gain, 1.94, 0.01);
  EXPECT_EQ(predictPolynomial(pts, 1.0, 1).degree, 1);
  EXPECT_EQ(predictPolynomial(pts, 1.0, 2).degree, 2);
}

TEST(TrackerPredictor, CubicMotionIsPredictedExactly) {
  auto cubic = [](double t) { return Eigen::Vector2d(3 + 10 * t - 2 * t * t + 0.7 * t * t * t, -4 + 1.5 * t * t * t); };
  // Timestamps like a KITTI utime in seconds: a raw Vandermonde matrix would be hopeless here.
  const double t0 = 1.3e9;
  const auto pts = sample(cubic, 10, t0, 0.1);
  const Eigen::Vector3d p = predictPolynomial(pts, t0 + 1.0).position;
  EXPECT_NEAR(p.x(), cubic(1.0).x(), 1e-6);
  EXPECT_NEAR(p.y(), cubic(1.0).y(), 1e-6);
  EXPECT_NEAR(p.z(), -0.8, 1e-12);
  EXPECT_EQ(predictPolynomial(pts, t0 + 1.0).degree, 3);
  // Three frames ahead (after misses), with the gain bound lifted so the cubic is kept.
  const Prediction q = predictPolynomial(pts, t0 + 1.2, 3, 100.0);
  EXPECT_EQ(q.degree, 3);
  EXPECT_NEAR(q.position.x(), cubic(1.2).x(), 1e-6);
  EXPECT_NEAR(q.position.y(), cubic(1.2).y(), 1e-6);
}

TEST(TrackerPredictor, LinearMotionIsPredictedExactlyAtAnyDegree) {
  auto line = [](double t) { return Eigen::Vector2d(1 + 12 * t, 2 - 3 * t); };
  for (int n : {2, 3, 4, 10}) {
    const auto pts = sample(line, n, 50.0, 0.1);
    const Eigen::Vector3d p = predictPolynomial(pts, 50.0 + 0.1 * n).position;
    EXPECT_NEAR(p.x(), line(0.1 * n).x(), 1e-9) << n;
    EXPECT_NEAR(p.y(), line(0.1 * n).y(), 1e-9) << n;
  }
  const auto one = sample(line, 1, 0.0, 0.1);
  EXPECT_TRUE(predictPolynomial(one, 0.5).position.isApprox(one[0].position));
  EXPECT_THROW(predictPolynomial({}, 0.0), std::invalid_argument);
}

TEST(TrackerPredictor, NoiseIsNotAmplified) {
  // A straight, noisy track: the one-step prediction error stays near the observation noise
  // (an exact cubic through the last four points would be 8x worse).
  std::mt19937 rng(1);
  std::normal_distribution<double> noise(0.0, 0.2);
  double sq = 0;
  const int trials = 2000;
  for (int k = 0; k < trials; ++k) {
    auto pts = sample([](double t) { return Eigen::Vector2d(10 * t, 0); }, 10, 0.0, 0.1);
    for (auto& p : pts) p.position.head<2>() += Eigen::Vector2d(noise(rng), noise(rng));
    sq += (predictPolynomial(pts, 1.0).position.head<2>() - Eigen::Vector2d(10, 0)).squaredNorm();
  }
  const double rms_per_axis = std::sqrt(sq / trials / 2);
  EXPECT_LT(rms_per_axis, 0.2 * 2.1);  // theory: 1.94 x sigma for the 10-point cubic
}

TEST(TrackerPredictor, WindowDisplacement) {
  const auto moving = sample([](double t) { return Eigen::Vector2d(3 * t, 4 * t); }, 10, 7.0, 0.1);
  EXPECT_NEAR(windowDisplacement(moving), 5 * 0.9, 1e-9);
  EXPECT_EQ(windowDisplacement(sample([](double) { return Eigen::Vector2d(1, 1); }, 1, 0, 0.1)), 0.0);

  // A parked car seen with 0.2 m noise: the fitted line hardly moves.
  std::mt19937 rng(2);
  std::normal_distribution<double> noise(0.0, 0.2);
  int above = 0;
  for (int k = 0; k < 1000; ++k) {
    auto pts = sample([](double) { return Eigen::Vector2d(5, 5); }, 10, 0.0, 0.1);
    for (auto& p : pts) p.position.head<2>() += Eigen::Vector2d(noise(rng), noise(rng));
    above += windowDisplacement(pts) > 1.0;
  }
  EXPECT_LT(above, 10);
}
