// A vehicle's speed along its heading from the ends of the side it shows (side_ends.hpp): the ends
// and their standard deviation, a crossing car's speed from scan to scan against the truth on a
// lidar whose columns fall anew each scan, the pairs refused when an end is hidden or a
// neighbour's points join, a young crossing car's published velocity with and without them, and
// a side cut short: which end something nearer hides, and the pairs and line of the end it saw.
#include <gtest/gtest.h>

#include <algorithm>
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

namespace {

// The side of a car 4.5 m long, its heading +y, square on 50 m ahead (its near face at x = 49.1):
// four rings (elevations -1.2 .. 0 deg) at the 0.18 deg columns, with a wall 80 m away behind it
// and, where `hidden_from` is below the car's front, something 30 m away hiding it from there on.
const double kStep18 = 0.18 * M_PI / 180.0;
struct SideScene {
  PointCloud scan;
  ObjectPoints car;
};
SideScene sideScene(double hidden_from = 10.0, bool ground = false) {
  std::vector<Eigen::Vector4f> columns;
  const auto add = [&](double range_x, double a, double e) {
    columns.emplace_back(range_x, range_x * std::tan(a), std::hypot(range_x, range_x * std::tan(a)) * std::tan(e), 0.0);
  };
  for (int j = -200; j <= 200; ++j) {
    const double a = (j + 0.5) * kStep18, y_car = 49.1 * std::tan(a);
    for (double e_deg : {-1.2, -0.8, -0.4, 0.0}) {
      const double e = e_deg * M_PI / 180.0;
      if (std::abs(y_car) <= 2.25 && y_car < hidden_from) add(49.1, a, e);
      else if (std::abs(y_car) <= 2.25 + 2.0 && y_car >= hidden_from) add(30.0, a, e);
      else add(80.0, a, e);
    }
    if (ground) add(30.0, a, -3.0 * M_PI / 180.0);  // the road 30 m away, below the car's rings
  }
  SideScene s;
  s.scan.resize(4, static_cast<Eigen::Index>(columns.size()));
  for (size_t i = 0; i < columns.size(); ++i) s.scan.col(static_cast<Eigen::Index>(i)) = columns[i];
  return s;
}
Box cropOf(double length) {
  Box crop;
  crop.center = Eigen::Vector3d(50.0, 0.0, -0.4);
  crop.size = Eigen::Vector3d(length, 2.2, 2.0);
  crop.yaw = M_PI / 2;
  return crop;
}
ObjectPoints pointsIn(const PointCloud& scan, const Box& crop) {
  ObjectPoints points;
  for (Eigen::Index i = 0; i < scan.cols(); ++i)
    if (crop.contains(scan.col(i).head<3>().cast<double>())) points.push_back(scan.col(i).head<3>());
  return points;
}

}  // namespace

TEST(SideEnds, AnEndIsHiddenWhereSomethingNearerIsBesideIt) {
  const Box crop = cropOf(4.5 + 1.4);
  // Nothing in front: the wall behind hides nothing, nor does the road below the car's rings.
  for (const bool ground : {false, true}) {
    const SideScene s = sideScene(10.0, ground);
    const AzimuthIndex index(s.scan, kStep18);
    const ObjectPoints car = pointsIn(s.scan, crop);
    const EndsSeen seen = endsSeen(index, car, crop);
    EXPECT_TRUE(seen.low);
    EXPECT_TRUE(seen.high);
  }
  // Something 30 m away hides the car from y = 1.25 on: its front (+y, high) end is hidden, its
  // back is not.
  const SideScene s = sideScene(1.25);
  const ObjectPoints car = pointsIn(s.scan, crop);
  const EndsSeen seen = endsSeen(AzimuthIndex(s.scan, kStep18), car, crop);
  EXPECT_TRUE(seen.low);
  EXPECT_FALSE(seen.high);
  EXPECT_NEAR(sideEnds(car, Eigen::Vector3d::UnitY())->high, 1.25, 0.16);
  // A crop that ends within a column's spacing (0.157 m here) of the ends may have cut them.
  const Box tight = cropOf(4.6);
  const SideScene whole = sideScene();
  const EndsSeen cut = endsSeen(AzimuthIndex(whole.scan, kStep18), pointsIn(whole.scan, tight), tight);
  EXPECT_FALSE(cut.low);
  EXPECT_FALSE(cut.high);
  // Named along -d, the ends swap.
  EXPECT_FALSE(seen.flipped(true).low);
  EXPECT_TRUE(seen.flipped(true).high);
}

TEST(SideEnds, TheAzimuthIndexWrapsAroundBehindTheSensor) {
  PointCloud scan(4, 3);
  scan.col(0) << std::cos(M_PI - 0.0005), std::sin(M_PI - 0.0005), 0, 0;
  scan.col(1) << std::cos(-M_PI + 0.0005), std::sin(-M_PI + 0.0005), 0, 0;
  scan.col(2) << 1, 0, 0, 0;
  const AzimuthIndex index(scan, kStep18);
  std::vector<int> near = index.near(M_PI - 0.002, M_PI + 0.002);
  std::sort(near.begin(), near.end());
  EXPECT_EQ(near, (std::vector<int>{0, 1}));
  EXPECT_EQ(index.near(-0.001, 0.001), std::vector<int>{2});
}

TEST(SideEnds, ASideCutShortCountsTheEndItSaw) {
  const double length = 4.5, tolerance = 0.5, box_sigma = 0.3;
  const SideEnds whole{-2.2, 2.2}, short_front{-2.2, 1.0};
  // As long as the car: both, whatever the test said.
  EXPECT_TRUE(endsThatCount(whole, EndsSeen{false, false}, 40, length, tolerance, 0.0, box_sigma, 20).both());
  // Short: the end the test saw, where the box puts it; both "seen" contradicts the test; too few
  // points, or an end 3 box sigmas from the box's, count for nothing.
  const EndsSeen back = endsThatCount(short_front, EndsSeen{true, false}, 40, length, tolerance, 0.0, box_sigma, 20);
  EXPECT_TRUE(back.low);
  EXPECT_FALSE(back.high);
  const auto none = [](const EndsSeen& e) { return !e.low && !e.high; };
  EXPECT_TRUE(none(endsThatCount(short_front, EndsSeen{}, 40, length, tolerance, 0.0, box_sigma, 20)));
  EXPECT_TRUE(none(endsThatCount(short_front, EndsSeen{true, false}, 19, length, tolerance, 0.0, box_sigma, 20)));
  EXPECT_TRUE(none(endsThatCount(short_front, EndsSeen{true, false}, 40, length, tolerance, 1.0, box_sigma, 20)));

  // A pair by its back end alone: that end's motion, its variance twice a middle's.
  const double s = 0.05, dt = 0.1;
  const SideView a{SideEnds{-2.2, 1.0}, s, EndsSeen{true, false}}, b{SideEnds{-1.2, 2.3}, s, EndsSeen{}};
  const std::optional<PairSpeed> p = sidePairSpeed(a, b, Eigen::Vector2d::UnitY(), length, tolerance, dt);
  ASSERT_TRUE(p);
  EXPECT_NEAR(p->speed, 10.0, 1e-9);
  EXPECT_NEAR(p->sigma, std::sqrt(2.0 * 2.0 * s * s) / dt, 1e-9);
  // No end both saw: nothing.
  EXPECT_FALSE(sidePairSpeed(a, SideView{b.ends, s, EndsSeen{false, true}}, Eigen::Vector2d::UnitY(), length, tolerance, dt));
}

TEST(SideEnds, TheLineTakesEachEndWithItsOwnOffset) {
  // A 4.4 m car at 10 m/s: two whole scans, one whose front is hidden, one whose back is, all on
  // the line: the slope is exact, its sigma that of each end's own regression on time.
  const double s = 0.05;
  std::vector<SideScan> scans = {{0.0, SideView{SideEnds{-2.2, 2.2}, s}},
                                 {0.1, SideView{SideEnds{-1.2, 3.2}, s}},
                                 {0.2, SideView{SideEnds{-0.2, 1.5}, s, EndsSeen{true, false}}},
                                 {0.3, SideView{SideEnds{2.0, 5.2}, s, EndsSeen{false, true}}}};
  std::optional<SideLine> line = sideLine(scans, 4.4, 0.5);
  ASSERT_TRUE(line);
  EXPECT_NEAR(line->speed, 10.0, 1e-9);
  // Back ends at 0, 0.1, 0.2 s (sum of squares about their mean 0.02), fronts at 0, 0.1, 0.3 s
  // (0.0467): sigma = s / sqrt(0.0667).
  EXPECT_NEAR(line->sigma, s / std::sqrt(0.02 + (0.14 / 3.0 * 1.0)), 1e-9);
  EXPECT_EQ(line->scans, 4);
  // Among three scans a one-end scan has nothing to be checked by: the line is the whole scans'.
  scans.pop_back();
  line = sideLine(scans, 4.4, 0.5);
  ASSERT_TRUE(line);
  EXPECT_EQ(line->scans, 2);
  EXPECT_NEAR(line->sigma, s / std::sqrt(2.0 * (0.0025 + 0.0025)), 1e-9);
}
