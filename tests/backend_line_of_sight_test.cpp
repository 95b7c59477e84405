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
  const auto pair = [](const Eigen::Vector2d& along, double speed, double sigma) {
    return PairSpeed{along, speed, sigma, 0.0, 0, std::nullopt};
  };
  // One pair caught the bonnet instead of the bumper: 15 m/s off.
  const std::optional<VelocityEvidence> v = medianPairVelocity({pair(u0, -24.8, 0.3), pair(u, -10.0, 0.3), pair(u, -25.1, 0.3)});
  ASSERT_TRUE(v);
  EXPECT_TRUE(v->velocity.isApprox(-24.8 * u, 1e-12));
  // Information along u (1 / 0.3^2), none across it.
  EXPECT_NEAR(u.dot(v->information * u), 1.0 / 0.09, 1e-9);
  const Eigen::Vector2d across(-u.y(), u.x());
  EXPECT_NEAR(across.dot(v->information * across), 0.0, 1e-12);
  // Two pairs: their mean.
  EXPECT_TRUE(medianPairVelocity({pair(u, -24.0, 0.3), pair(u, -25.0, 0.3)})->velocity.isApprox(-24.5 * u, 1e-12));
  EXPECT_FALSE(medianPairVelocity({}));
  // The median pair's standard deviation: 0.4.
  EXPECT_NEAR(u.dot(medianPairVelocity({pair(u, -24.0, 0.3), pair(u, -25.0, 0.4), pair(u, -24.5, 0.6)})->information * u), 1.0 / 0.16,
              1e-9);
}

TEST(LineOfSight, AFewPointPairCountsOnlyWhereAnotherAgrees) {
  const Eigen::Vector2d u(1, 0);
  const auto pair = [&](double speed, int points) { return PairSpeed{u, speed, 0.3, 0.0, points, std::nullopt}; };
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

// The face's ranges of six scans 0.1 s apart of a car closing at 25 m/s, 2 cm of noise, with one
// scan whose rings reached the bonnet (0.6 m farther): the repeated-median line leaves out that
// scan alone, wherever it lies, and judges nothing where too few scans or too many jumps tell.
TEST(LineOfSight, TheFacesScansOffItsLineAreTheJumps) {
  const std::vector<double> t = {-0.5, -0.4, -0.3, -0.2, -0.1, 0.0};
  const std::vector<double> noise = {0.01, -0.02, 0.015, 0.0, -0.01, 0.02};
  for (size_t jump = 0; jump < t.size(); ++jump) {
    std::vector<double> y;
    for (size_t i = 0; i < t.size(); ++i) y.push_back(60.0 - 25.0 * t[i] + noise[i] + (i == jump ? 0.6 : 0.0));
    const std::vector<bool> on = faceSamplesOnLine(t, y, 0.15);
    ASSERT_EQ(on.size(), t.size());
    for (size_t i = 0; i < t.size(); ++i) EXPECT_EQ(on[i], i != jump) << "jump at " << jump << ", sample " << i;
  }
  // Four scans, the first of them the jump: the Theil-Sen line (the median of all six pairwise
  // slopes, -26.8 m/s) judged the other three off it too; the repeated median's is theirs.
  const std::vector<double> t4 = {-0.3, -0.2, -0.1, 0.0}, y4 = {228.61, 225.40, 222.87, 220.31};
  EXPECT_EQ(faceSamplesOnLine(t4, y4, 0.15), std::vector<bool>({false, true, true, true}));
  // Three scans tell no jump from a change of speed.
  EXPECT_TRUE(faceSamplesOnLine({-0.2, -0.1, 0.0}, {65.0, 62.5, 60.0}, 0.15).empty());
  // A range that zigzags from ring to ring: half the scans off any line, none judged on it.
  EXPECT_EQ(faceSamplesOnLine(t, {72.5, 70.5, 70.0, 68.0, 67.5, 65.5}, 0.15), std::vector<bool>(6, false));
}

TEST(LineOfSight, AJudgedPairCountsByItsVerdictWhateverItsPoints) {
  const Eigen::Vector2d u(1, 0);
  const auto pair = [&](double speed, int points, std::optional<bool> on_line) {
    return PairSpeed{u, speed, 0.3, 0.0, points, on_line};
  };
  // A 12-point pair on its face's line counts alone; a 40-point one off it never does.
  EXPECT_TRUE(countsAlone(pair(-25.0, 12, true), 20));
  EXPECT_FALSE(countsAlone(pair(-31.0, 40, false), 20));
  EXPECT_TRUE(countsAlone(pair(-25.0, 20, std::nullopt), 20));
  EXPECT_TRUE(medianPairVelocity({pair(-31.0, 40, false), pair(-25.2, 12, true)}, 20)->velocity.isApprox(-25.2 * u, 1e-12));
  // An unjudged few-point pair is not saved by agreeing with one judged off its line.
  EXPECT_FALSE(medianPairVelocity({pair(-31.0, 40, false), pair(-31.2, 12, std::nullopt)}, 20));
}

namespace {

// A car at 15 m/s that brakes at 3 m/s^2 from t_brake on: the distance it has driven and its
// speed at time t.
std::pair<double, double> brakingCar(double t, double t_brake) {
  const double tb = std::clamp(t - t_brake, 0.0, 5.0);
  return {15.0 * std::min(t, t_brake) + 15.0 * tb - 1.5 * tb * tb, t < t_brake ? 15.0 : 15.0 - 3.0 * tb};
}

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
  const auto along = [](double t) { return brakingCar(t, 1.0); };
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
  const auto along = [](double t) { return brakingCar(t, 0.5); };
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

namespace {

// The braking oncoming car of brakingOncomingCar (100 m ahead at 15 m/s, 3 m/s^2 from 1 s on, an
// ego at 5 m/s, boxes 0.36 m off) scanned whole, its face the box's front: the RMS error of its
// published velocity from frame 12 to 30. In every fifth scan its rings reach the bonnet instead
// (bonnet_every: the face 0.6 m farther, its points pushed along their lines of sight), or the
// detector misses it in every third frame (miss_every; its points are still in the scan, which
// the backend crops from: BackendInput::scan). Over ten drives.
double brakingCarError(const BackendConfig& c, int bonnet_every, int miss_every, int* missed_measured = nullptr) {
  const auto along = [](double t) { return brakingCar(t, 1.0); };
  double sq = 0;
  int n = 0;
  for (unsigned seed = 1; seed <= 10; ++seed) {
  SimScene scene = oneCar([along](double t) { return planarPose(100.0 - along(t).first, 3.5, M_PI); }, 0.36);
  scene.ego = constantTwist(Pose::Identity(), 5.0, 0.0);
  scene.seed = seed;
  SlidingWindow window(c);
  std::mt19937 rng(seed);
  for (BackendInput in : scene.generate(31)) {
    const Pose car = scene.egoTruth(in.frame).inverse() * scene.objectTruth(1, in.frame);
    ObjectPoints points = scanBox(car, kCar, Eigen::Vector3d::Zero(), rng);
    if (bonnet_every > 0 && in.frame % bonnet_every == 0)
      for (Eigen::Vector3f& p : points) p += 0.6f * Eigen::Vector3f(p.x(), p.y(), 0.0f).normalized();
    auto scan = std::make_shared<PointCloud>(4, static_cast<Eigen::Index>(points.size()));
    for (size_t i = 0; i < points.size(); ++i) scan->col(static_cast<Eigen::Index>(i)) << points[i], 0.0f;
    in.scan = scan;
    if (miss_every > 0 && in.frame > 3 && in.frame % miss_every == 0) in.observations.clear();
    const BackendOutput out = window.process(in);
    if (missed_measured) *missed_measured += out.missed_vehicles_measured;
    if (in.frame < 12) continue;
    for (const TrackEstimate& e : out.tracks) {
      sq += (e.velocity.head<2>() - Eigen::Vector2d(-along(scene.time(in.frame)).second, 0.0)).squaredNorm();
      ++n;
    }
  }
  }
  EXPECT_GE(n, 150);
  return std::sqrt(sq / std::max(n, 1));
}

}  // namespace

// A face of 20 points or more counted alone, and its chain's robust loss let the bonnet's pairs (6
// m/s off, in and out) pull the velocity. Judged by the face's other scans, both are left out.
TEST(LineOfSight, AFaceThatJumpsToTheBonnetIsLeftOutByItsOtherScans) {
  BackendConfig judged = registrationHeldOff(), unjudged = judged;
  unjudged.line_of_sight_series = 0;
  const double clean = brakingCarError(judged, 0, 0), with = brakingCarError(judged, 5, 0),
               without = brakingCarError(unjudged, 5, 0);
  std::printf("braking car, a bonnet in every fifth scan: velocity RMSE %.3f m/s judged by its face's scans, %.3f "
              "not; %.3f without the bonnet\n", with, without, clean);
  EXPECT_LT(with, 0.6 * without);
  EXPECT_LT(with, 1.5 * clean);
}

// The detector missed the car in every third frame: without its points there, every missed scan
// broke two of the face's pairs. Measured there, the error is lower by more than twice an RMSE's
// own uncertainty over these ~190 outputs (1 / sqrt(2n), 5 %); the boxes it missed stay missing.
TEST(LineOfSight, AMissedCarIsMeasuredInTheScanWhereItsChainPredictsIt) {
  BackendConfig c = registrationHeldOff(), off = c;
  off.registration_missed_vehicles = false;
  int measured = 0, measured_off = 0;
  const double clean = brakingCarError(c, 0, 0), with = brakingCarError(c, 0, 3, &measured),
               without = brakingCarError(off, 0, 3, &measured_off);
  std::printf("braking car missed in every third frame: velocity RMSE %.3f m/s measured there (%d scans), %.3f not; "
              "%.3f never missed\n", with, measured, without, clean);
  EXPECT_GE(measured, 80);
  EXPECT_EQ(measured_off, 0);
  EXPECT_LT(with, 0.9 * without);
  EXPECT_GT(with, clean);
}
