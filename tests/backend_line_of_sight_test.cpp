// A far vehicle's speed along the line of sight from the face it shows (line_of_sight.hpp): the
// face's range on a 64-beam scan of an oncoming car, its speed from scan to scan against the
// truth, the head-on test, and the median that leaves one bad pair out.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <cstdio>

#include "backend/line_of_sight.hpp"
#include "backend/sliding_window.hpp"
#include "one_car_scene.hpp"

using namespace dlslot;
using namespace dlslot::backend;
using namespace dlslot::backend::test;

TEST(LineOfSight, TheFacesRangeIgnoresAStrayPointAndTheBodyBehindIt) {
  ObjectPoints points;
  for (int i = 0; i < 30; ++i) points.emplace_back(50.0f, -0.9f + 0.06f * i, 0.5f);   // the face
  for (int i = 0; i < 30; ++i) points.emplace_back(51.0f + 0.1f * i, 0.0f, 1.2f);     // bonnet, roof
  points.emplace_back(44.0f, 0.0f, 0.5f);                                              // a stray return
  const std::optional<double> range = nearFaceRange(points, Eigen::Vector3d::UnitX());
  ASSERT_TRUE(range);
  EXPECT_NEAR(*range, 50.0, 1e-6);
  EXPECT_FALSE(nearFaceRange({}, Eigen::Vector3d::UnitX()));
}

TEST(LineOfSight, AnOncomingCarsSpeedFromScanToScan) {
  // A car 90 -> 72 m ahead, coming at 25 m/s, on a 64-beam scan (1 cm range noise): 10-40 points.
  std::mt19937 rng(3);
  const double speed = -25.0, dt = 0.1;
  std::optional<double> before;
  Eigen::Vector3d u = Eigen::Vector3d::UnitX();
  int pairs = 0;
  for (int k = 0; k < 8; ++k) {
    const Pose car = planarPose(90.0 + speed * dt * k, 3.5, M_PI, 0.75);
    const ObjectPoints points = scanBox(car, kCar, kSensor, rng);
    ASSERT_GE(points.size(), 10u) << "scan " << k;
    Box box;
    box.center = car.translation();
    box.yaw = M_PI;
    EXPECT_TRUE(facesTheSensor(box, 10.0));  // 3.5 m beside the axis at 72-90 m: 2-3 deg
    if (before) {
      const double v = (*nearFaceRange(points, u) - *before) / dt;
      EXPECT_NEAR(v, speed * u.x(), 0.3) << "scan " << k;  // a box's flat front: within the noise
      ++pairs;
    }
    u = *lineOfSight(points, kSensor);
    before = nearFaceRange(points, u);
  }
  EXPECT_EQ(pairs, 7);
}

TEST(LineOfSight, OnlyAFrontOrBackFacingTheSensorCounts) {
  Box box;
  box.center = Eigen::Vector3d(30, 30, 0);  // bearing 45 deg
  for (double yaw_deg : {45.0, 225.0, 53.0, 37.0}) {
    box.yaw = yaw_deg * M_PI / 180.0;
    EXPECT_TRUE(facesTheSensor(box, 10.0)) << yaw_deg;
  }
  for (double yaw_deg : {57.0, 30.0, 135.0}) {  // turned 12-90 deg: a side shows
    box.yaw = yaw_deg * M_PI / 180.0;
    EXPECT_FALSE(facesTheSensor(box, 10.0)) << yaw_deg;
  }
}

TEST(LineOfSight, TheMedianPairAlongTheNewestLineOfSightOnly) {
  const Eigen::Vector2d u0(1, 0), u(0.8, 0.6);
  // One pair caught the bonnet instead of the bumper: 15 m/s off.
  const std::optional<VelocityEvidence> v = medianPairVelocity({{u0, -24.8, 0.3}, {u, -10.0, 0.3}, {u, -25.1, 0.3}});
  ASSERT_TRUE(v);
  EXPECT_TRUE(v->velocity.isApprox(-24.8 * u, 1e-12));
  // Information along u (1 / 0.3^2), none across it.
  EXPECT_NEAR(u.dot(v->information * u), 1.0 / 0.09, 1e-9);
  const Eigen::Vector2d across(-u.y(), u.x());
  EXPECT_NEAR(across.dot(v->information * across), 0.0, 1e-12);
  // Two pairs: their mean.
  EXPECT_TRUE(medianPairVelocity({{u, -24.0, 0.3}, {u, -25.0, 0.3}})->velocity.isApprox(-24.5 * u, 1e-12));
  EXPECT_FALSE(medianPairVelocity({}));
  // The median pair's standard deviation: 0.4.
  EXPECT_NEAR(u.dot(medianPairVelocity({{u, -24.0, 0.3}, {u, -25.0, 0.4}, {u, -24.5, 0.6}})->information * u), 1.0 / 0.16,
              1e-9);
}

TEST(LineOfSight, AFewPointPairCountsOnlyWhereAnotherAgrees) {
  const Eigen::Vector2d u(1, 0);
  const auto pair = [&](double speed, int points) { return PairSpeed{u, speed, 0.3, 0.0, points}; };
  // A car's first pairs, the second from 11 points on the bonnet: neither counts alone; before,
  // their mean was 5 m/s.
  EXPECT_FALSE(medianPairVelocity({pair(-1.13, 15), pair(11.2, 11)}, 20));
  // Two that agree within 2 sigma count, the stray one does not (the median of the two).
  EXPECT_TRUE(medianPairVelocity({pair(-1.1, 15), pair(11.2, 11), pair(-1.5, 12)}, 20)
                  ->velocity.isApprox(-1.3 * u, 1e-12));
  // A pair of 20 points or more counts alone, and lets a few-point pair that agrees with it count.
  EXPECT_TRUE(medianPairVelocity({pair(-1.2, 25)}, 20)->velocity.isApprox(-1.2 * u, 1e-12));
  EXPECT_TRUE(medianPairVelocity({pair(-1.2, 25), pair(-1.0, 12), pair(5.0, 12)}, 20)
                  ->velocity.isApprox(-1.1 * u, 1e-12));
  // Without a point threshold every pair counts, as before.
  EXPECT_TRUE(medianPairVelocity({pair(-1.13, 15), pair(11.2, 11)})->velocity.isApprox(5.035 * u, 1e-12));
}

namespace {

// A young oncoming car 70 -> 55 m ahead at 25 m/s, its boxes as far off as the backend's noise
// model says (0.105 m x (1 + 0.035 x 65 m) = 0.34 m, config/dlslot.yaml), the ego stopped: the RMS
// error of its published velocity over its young frames, with and without the line of sight.
double youngVelocityError(int line_of_sight_pairs) {
  const SimScene scene = oneCar(constantTwist(planarPose(70.0, 3.5, M_PI, -1.73 + 0.75), 25.0, 0.0), 0.34);
  BackendConfig c = registrationHeldOff();
  c.line_of_sight_pairs = line_of_sight_pairs;
  // From frame 4 on: two scan pairs at least.
  const VelocityErrors e = publishedVelocityErrors(scene, c, 7, 4, Eigen::Vector2d(-25.0, 0.0), 5);
  EXPECT_GE(e.count, 3);
  return e.rmse;
}

}  // namespace

TEST(LineOfSight, AYoungFarCarsVelocityFromItsFaceNotItsBoxesAlone) {
  const double with = youngVelocityError(3), without = youngVelocityError(0);
  EXPECT_LT(with, 0.5);
  EXPECT_GT(without, 2 * with);
}

namespace {

// An oncoming car 100 m ahead at 15 m/s that brakes at 3 m/s^2 from 1 s on, seen head-on by an ego
// driving at 5 m/s, its boxes as far off as the backend's noise model says at 70 m (0.105 m x
// (1 + 0.035 x 70 m) = 0.36 m): the RMS and mean error of its published velocity from frame 12 (its chain spans the window) to 30
// (braking; 40 m away at the end), with and without the line of sight on its chain.
struct BrakingErrors {
  double rmse = 0, mean = 0;
};
BrakingErrors brakingOncomingCar(bool on_chain) {
  const auto along = [](double t) {  // distance driven and speed
    const double tb = std::clamp(t - 1.0, 0.0, 5.0);
    return std::make_pair(15.0 * std::min(t, 1.0) + 15.0 * tb - 1.5 * tb * tb, t < 1.0 ? 15.0 : 15.0 - 3.0 * tb);
  };
  SimScene scene = oneCar([along](double t) { return planarPose(100.0 - along(t).first, 3.5, M_PI); }, 0.36);
  scene.ego = constantTwist(Pose::Identity(), 5.0, 0.0);
  BackendConfig c = registrationHeldOff();
  c.line_of_sight_chain = on_chain;
  SlidingWindow window(c);
  std::mt19937 rng(6);
  double sq = 0, sum = 0;
  int n = 0;
  for (BackendInput in : scene.generate(31)) {
    scanTheCar(scene, in, rng);
    const BackendOutput out = window.process(in);
    if (in.frame < 12) continue;
    for (const TrackEstimate& e : out.tracks) {
      const double truth = -along(scene.time(in.frame)).second;  // toward the ego, world x
      sq += (e.velocity.head<2>() - Eigen::Vector2d(truth, 0.0)).squaredNorm();
      sum += e.velocity.x() - truth;
      ++n;
    }
  }
  EXPECT_GE(n, 15);
  return {std::sqrt(sq / std::max(n, 1)), sum / std::max(n, 1)};
}

}  // namespace

// Its boxes alone (0.36 m) measure the braking late: the chain's velocity trails the car, too fast
// toward the ego. The face's range, scan to scan, measures it to centimetres.
TEST(LineOfSight, AnOncomingCarBrakingIsFollowedByItsFaceOnTheChain) {
  const BrakingErrors with = brakingOncomingCar(true), without = brakingOncomingCar(false);
  std::printf("braking oncoming car: velocity RMSE %.3f m/s (mean %+.3f) with the line of sight on its chain, "
              "%.3f (%+.3f) without\n", with.rmse, with.mean, without.rmse, without.mean);
  EXPECT_LT(with.rmse, 0.6 * without.rmse);
  EXPECT_LT(std::abs(with.mean), 0.5 * std::abs(without.mean));
}

namespace {

// An oncoming car 55 m ahead at 15 m/s that brakes at 3 m/s^2 from 0.5 s on, seen head-on by an
// ego driving at 5 m/s, its boxes as far off as the backend's noise model says at 70 m (0.36 m),
// its face of 20 points or more: over 30 drives, the RMS error of its published velocity at each
// frame.
std::vector<double> brakingOncomingErrorByFrame() {
  constexpr int kFrames = 18, kDrives = 30;
  const auto along = [](double t) {  // distance driven and speed
    const double tb = std::clamp(t - 0.5, 0.0, 5.0);
    return std::make_pair(15.0 * std::min(t, 0.5) + 15.0 * tb - 1.5 * tb * tb, t < 0.5 ? 15.0 : 15.0 - 3.0 * tb);
  };
  std::vector<double> sq(kFrames, 0.0);
  std::vector<int> n(kFrames, 0);
  for (int drive = 0; drive < kDrives; ++drive) {
    SimScene scene = oneCar([along](double t) { return planarPose(55.0 - along(t).first, 3.5, M_PI); }, 0.36);
    scene.ego = constantTwist(Pose::Identity(), 5.0, 0.0);
    SlidingWindow window(registrationHeldOff());
    std::mt19937 rng(100 + drive);
    for (BackendInput in : scene.generate(kFrames)) {
      scanTheCar(scene, in, rng);
      const double truth = -along(scene.time(in.frame)).second;  // toward the ego, world x
      for (const TrackEstimate& e : window.process(in).tracks) {
        sq[in.frame] += (e.velocity.head<2>() - Eigen::Vector2d(truth, 0.0)).squaredNorm();
        ++n[in.frame];
      }
    }
  }
  std::vector<double> rms(kFrames, NAN);
  for (int f = 0; f < kFrames; ++f)
    if (n[f] > 0) rms[f] = std::sqrt(sq[f] / n[f]);
  return rms;
}

}  // namespace

// Its velocity is read from its chain from frame 11 on (the chain spans the window). The chain
// then has the faces' speeds the young path read in the window before, and its error does not jump
// there. It had: the chain took only the pairs after its first read, and its first reads trailed
// the braking by the boxes' alone (1.15 / 1.05 / 0.69 m/s at frames 11-13, against 0.52 at 10).
TEST(LineOfSight, AChainReadForTheFirstTimeKeepsTheFacesTheYoungPathRead) {
  const std::vector<double> rms = brakingOncomingErrorByFrame();
  for (size_t f = 0; f < rms.size(); ++f) std::printf("frame %zu: %.3f m/s\n", f, rms[f]);
  const double young = std::max({rms[8], rms[9], rms[10]});
  for (int f = 11; f < static_cast<int>(rms.size()); ++f) EXPECT_LT(rms[f], 1.5 * young) << "frame " << f;
}
