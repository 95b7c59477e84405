// A vehicle's speed along its heading from the ends of the side it shows (side_ends.hpp): the ends
// and their standard deviation, a crossing car's speed from scan to scan against the truth on a
// lidar whose columns fall anew each scan, the pairs refused when an end is hidden or a
// neighbour's points join, and a young crossing car's published velocity with and without them.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "backend/side_ends.hpp"
#include "backend/sliding_window.hpp"
#include "one_car_scene.hpp"

using namespace dlslot;
using namespace dlslot::backend;
using namespace dlslot::backend::test;

namespace {
const double kStep = 0.17 * M_PI / 180.0;  // object_scan.hpp's columns

// A car crossing 50 m ahead (heading +y), its centre at y, scanned with the columns shifted by
// `phase` of one.
ObjectPoints crossingCar(double y, double phase, std::mt19937& rng) {
  return scanBox(planarPose(50.0, y, M_PI / 2, 0.75), kCar, kSensor, rng, 0.01, false, 0.3, phase);
}
}  // namespace

TEST(SideEnds, TheExtremesAlongTheHeadingAndOneEndsSigma) {
  const ObjectPoints points = {{50.0f, -2.0f, 0.5f}, {50.2f, 2.2f, 1.0f}, {49.9f, 0.3f, 0.8f}};
  const std::optional<SideEnds> e = sideEnds(points, Eigen::Vector3d::UnitY());
  ASSERT_TRUE(e);
  EXPECT_NEAR(e->low, -2.0, 1e-6);
  EXPECT_NEAR(e->high, 2.2, 1e-6);
  EXPECT_NEAR(e->middle(), 0.1, 1e-6);
  EXPECT_FALSE(sideEnds({{1.0f, 2.0f, 3.0f}}, Eigen::Vector3d::UnitY()));
  // 50 m, seen square on, 0.18 deg columns: 0.157 m apart, uniform over them 0.0453 m; with a 0.02
  // m floor 0.0495. Seen at 30 deg from the line of sight, the columns are twice as far apart.
  const double step = 0.18 * M_PI / 180.0;
  EXPECT_NEAR(sideEndSigma(50.0, 1.0, step, 0.02), std::hypot(50.0 * step / std::sqrt(12.0), 0.02), 1e-12);
  EXPECT_NEAR(sideEndSigma(50.0, 1.0, step, 0.02), 0.0495, 1e-4);
  EXPECT_NEAR(sideEndSigma(50.0, 0.5, step, 0.0), 2.0 * sideEndSigma(50.0, 1.0, step, 0.0), 1e-12);
}

// 50 m ahead a box is 0.29 m off (0.105 m x (1 + 0.035 x 50), config/dlslot.yaml): two boxes 0.1 s
// apart give its speed to 4.1 m/s. The side's ends, scan to scan, to decimetres a second.
TEST(SideEnds, ACrossingCarsSpeedFromScanToScan) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> phase(0.0, 1.0);
  const double speed = 10.0, dt = 0.1;
  const Eigen::Vector3d d = Eigen::Vector3d::UnitY();
  std::optional<SideView> before;
  double sq = 0, claimed_sq = 0;
  int pairs = 0, scans = 0;
  for (int k = 0; k <= 30; ++k, ++scans) {  // 15 m before the crossing to 15 m after
    const double y = -15.0 + speed * dt * k;
    const ObjectPoints points = crossingCar(y, phase(rng), rng);
    const double range = std::hypot(50.0, y);
    const SideView view{*sideEnds(points, d), sideEndSigma(range, 50.0 / range, kStep, 0.02)};
    if (before)
      if (const std::optional<PairSpeed> p = sidePairSpeed(*before, view, d.head<2>(), kCar.x(), 0.5, dt)) {
        sq += std::pow(p->speed - speed, 2);
        claimed_sq += p->sigma * p->sigma;
        ++pairs;
      }
    before = view;
  }
  const double claimed = std::sqrt(claimed_sq / pairs);
  // Nothing hides either end: every pair counts.
  EXPECT_EQ(pairs, scans - 1);
  const double rmse = std::sqrt(sq / pairs);
  std::printf("crossing car 50 m: side pairs' speed RMSE %.3f m/s, claimed sigma (RMS) %.3f\n", rmse, claimed);
  EXPECT_LT(rmse, 0.6);
  // The claimed sigma is sqrt(2) the independent pair's (side_ends.hpp): above the error, not far.
  EXPECT_LT(rmse, claimed);
  EXPECT_GT(rmse, 0.4 * claimed);
}

TEST(SideEnds, APairIsRefusedWhenAnEndIsHiddenOrANeighboursPointsJoin) {
  std::mt19937 rng(12);
  const Eigen::Vector3d d = Eigen::Vector3d::UnitY();
  const double sigma_end = sideEndSigma(50.0, 1.0, kStep, 0.02);
  const ObjectPoints first = crossingCar(0.0, 0.3, rng), second = crossingCar(1.0, 0.7, rng);
  const SideView a{*sideEnds(first, d), sigma_end}, b{*sideEnds(second, d), sigma_end};
  ASSERT_TRUE(sidePairSpeed(a, b, d.head<2>(), kCar.x(), 0.5, 0.1));
  // Its front hidden behind something from the second scan on: the middle would move 0.4 m less.
  ObjectPoints hidden;
  for (const Eigen::Vector3f& p : second)
    if (p.y() < 2.45f) hidden.push_back(p);
  EXPECT_FALSE(sidePairSpeed(a, SideView{*sideEnds(hidden, d), sigma_end}, d.head<2>(), kCar.x(), 0.5, 0.1));
  // A car close behind in the crop of both scans: 5.5 m or more where the car is 4.5.
  ObjectPoints joined_a = first, joined_b = second;
  for (const Eigen::Vector3f& p : crossingCar(-5.0, 0.3, rng)) joined_a.push_back(p);
  for (const Eigen::Vector3f& p : crossingCar(-4.0, 0.7, rng)) joined_b.push_back(p);
  EXPECT_FALSE(sidePairSpeed(SideView{*sideEnds(joined_a, d), sigma_end}, SideView{*sideEnds(joined_b, d), sigma_end},
                             d.head<2>(), kCar.x(), 0.5, 0.1));
  // A view without a finite sigma counts for nothing.
  EXPECT_FALSE(sidePairSpeed(a, SideView{b.ends, std::nan("")}, d.head<2>(), kCar.x(), 0.5, 0.1));
}

TEST(SideEnds, TheLineThroughTheMiddlesTakesEachScanOnce) {
  // Four scans 0.1 s apart of a 4.5 m car at 10 m/s, each middle 5 cm off the line (+, -, +, -):
  // the weighted least-squares slope and its sigma, s / sqrt(2) per middle over sqrt(sum (t - t_mean)^2).
  const double s = 0.05;
  std::vector<SideScan> scans;
  for (int k = 0; k < 4; ++k) {
    const double middle = 1.0 * k + (k % 2 ? -0.01 : 0.01);
    scans.push_back({0.1 * k, SideView{SideEnds{middle - 2.2, middle + 2.2}, s}});
  }
  std::optional<SideLine> line = sideLine(scans, 4.5, 0.5);
  ASSERT_TRUE(line);
  // The slope of (+1, -1, +1, -1) cm at t - t_mean = -0.15, -0.05, 0.05, 0.15 s: -0.002 / 0.05.
  EXPECT_NEAR(line->speed, 10.0 - 0.04, 1e-9);
  EXPECT_NEAR(line->sigma, (s / std::sqrt(2.0)) / std::sqrt(0.05), 1e-9);
  EXPECT_NEAR(line->time, 0.15, 1e-12);
  EXPECT_EQ(line->scans, 4);
  // A scan whose front was hidden (its length 1 m short) and one whose middle is 0.5 m off (ten
  // of its sigmas: a stray point beyond an end): both left out, the line as before.
  std::vector<SideScan> bad = scans;
  bad.push_back({0.4, SideView{SideEnds{4.0 - 2.2, 4.0 + 1.2}, s}});
  bad.push_back({0.5, SideView{SideEnds{5.5 - 2.2, 5.5 + 2.2}, s}});
  line = sideLine(bad, 4.5, 0.5);
  ASSERT_TRUE(line);
  EXPECT_EQ(line->scans, 4);
  EXPECT_NEAR(line->speed, 10.0 - 0.04, 1e-9);
  // One scan is no line; nor one and a scan without a finite sigma.
  EXPECT_FALSE(sideLine({scans.front()}, 4.5, 0.5));
  EXPECT_FALSE(sideLine({scans[0], SideScan{0.1, SideView{scans[1].view.ends, std::nan("")}}}, 4.5, 0.5));
}

namespace {

// A young car crossing 50 m ahead at 10 m/s, its boxes as far off as the backend's noise model says
// there (0.29 m), the ego stopped, the registration held off (no car has 100 000 points): the RMS
// error of its published velocity over its first frames, with and without its side's ends.
double youngCrossingError(double side_azimuth_step_deg) {
  const SimScene scene = oneCar(constantTwist(planarPose(50.0, -4.0, M_PI / 2, -1.73 + 0.75), 10.0, 0.0), 0.29);
  BackendConfig c = registrationHeldOff();
  c.side_azimuth_step_deg = side_azimuth_step_deg;
  // From frame 4 on: three boxes at least.
  const VelocityErrors e = publishedVelocityErrors(scene, c, 9, 4, Eigen::Vector2d(0.0, 10.0), 13, true);
  EXPECT_GE(e.count, 4);
  return e.rmse;
}

}  // namespace

TEST(SideEnds, AYoungCrossingCarsVelocityFromItsSidesEnds) {
  const double with = youngCrossingError(0.17), without = youngCrossingError(0.0);
  std::printf("young crossing car 50 m: velocity RMSE %.3f m/s with its side's ends, %.3f without\n", with, without);
  EXPECT_LT(with, 0.2);
  EXPECT_LT(with, 0.3 * without);
}
