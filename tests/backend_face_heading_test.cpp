// A vehicle's heading from the faces its points show (face_heading.hpp): the fit against the
// truth on a 64-beam scan of a box-shaped car from several sides, what it refuses, and the
// factor's effect on a car's published heading and sideways velocity in the window.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "backend/face_heading.hpp"
#include "backend/sliding_window.hpp"
#include "one_car_scene.hpp"

using namespace dlslot;
using namespace dlslot::backend;
using namespace dlslot::backend::test;

namespace {

constexpr double kDeg = M_PI / 180.0;

// The detector's box of a car at `truth`: its centre and heading off by the given amounts.
Box detectorBox(const Pose& truth, double dx, double dy, double dyaw) {
  Box b;
  b.center = truth.translation() + Eigen::Vector3d(dx, dy, 0.0);
  b.size = kCar;
  b.yaw = yawOf(truth.linear()) + dyaw;
  return b;
}

double angleError(double a, double b) { return std::remainder(a - b, M_PI); }

}  // namespace

TEST(FaceHeading, ACarsVisibleSidesGiveItsHeading) {
  // Cars 8-40 m away, seen from behind, ahead at an angle, beside and oncoming; their boxes 0.2 m
  // and 3 deg off (a detector's), range noise 1 cm.
  std::mt19937 rng(11);
  int measured = 0;
  for (const Pose& car : {planarPose(15, 0.3, 0.02, 0.75), planarPose(25, 6, 0.3, 0.75), planarPose(3, -8, -0.1, 0.75),
                          planarPose(40, -3.5, M_PI + 0.05, 0.75), planarPose(-12, 4, 1.2, 0.75),
                          planarPose(20, 20, -2.0, 0.75)}) {
    const ObjectPoints points = scanBox(car, kCar, kSensor, rng);
    const std::optional<FaceHeading> face = faceHeading(points, detectorBox(car, 0.2, -0.15, 3 * kDeg), kSensor);
    ASSERT_TRUE(face) << car.translation().transpose();
    const double error = angleError(face->yaw, yawOf(car.linear()));
    EXPECT_LT(std::abs(error), 0.2 * kDeg) << car.translation().transpose();
    EXPECT_LT(std::abs(error), 3 * face->sigma) << car.translation().transpose();
    EXPECT_LT(face->sigma, 1.0 * kDeg);
    ++measured;
  }
  EXPECT_EQ(measured, 6);
}

TEST(FaceHeading, TheGroundAndANeighboursPointsInTheBoxDoNotTurnIt) {
  std::mt19937 rng(12);
  const Pose car = planarPose(18, 5, 0.4, 0.75);
  ObjectPoints points = scanBox(car, kCar, kSensor, rng, 0.01, true, 0.5);
  // A neighbour's corner 0.3 m beyond the car's front, inside the loose box.
  const Pose neighbour = car * planarPose(4.8, 0.9, 0.3);
  for (const Eigen::Vector3f& p : scanBox(neighbour, kCar, kSensor, rng)) {
    const Eigen::Vector3d q = car.inverse() * p.cast<double>();
    if (std::abs(q.x()) < 2.25 + 0.4 && std::abs(q.y()) < 0.9 + 0.4) points.push_back(p);
  }
  const std::optional<FaceHeading> face = faceHeading(points, detectorBox(car, -0.1, 0.2, -4 * kDeg), kSensor);
  ASSERT_TRUE(face);
  EXPECT_LT(std::abs(angleError(face->yaw, 0.4)), 0.3 * kDeg);
}

TEST(FaceHeading, NothingWithoutFacesToFit) {
  std::mt19937 rng(13);
  const Pose far = planarPose(110, 20, 0.7, 0.75);  // a few points on a ring or two
  const ObjectPoints sparse = scanBox(far, kCar, kSensor, rng);
  EXPECT_FALSE(faceHeading(sparse, detectorBox(far, 0, 0, 0), kSensor));
  const Pose near = planarPose(12, 2, 0.1, 0.75);
  const ObjectPoints points = scanBox(near, kCar, kSensor, rng);
  ASSERT_TRUE(faceHeading(points, detectorBox(near, 0, 0, 0), kSensor));
  // A sensor inside the box's footprint sees no face of it; a box turned 20 deg from the points'
  // faces is another object's (the fit would leave it beyond max_turn_rad).
  EXPECT_FALSE(faceHeading(points, detectorBox(near, 0, 0, 0), near.translation()));
  EXPECT_FALSE(faceHeading(points, detectorBox(near, 0, 0, 20 * kDeg), kSensor));
  EXPECT_FALSE(faceHeading({}, detectorBox(near, 0, 0, 0), kSensor));
  // Points that are not numbers (a corrupt scan) are no points.
  ObjectPoints corrupt = points;
  for (int i = 0; i < 50; ++i) corrupt.emplace_back(NAN, NAN, NAN);
  const std::optional<FaceHeading> face = faceHeading(corrupt, detectorBox(near, 0, 0, 0), kSensor);
  ASSERT_TRUE(face);
  EXPECT_TRUE(std::isfinite(face->yaw) && std::isfinite(face->sigma));
  EXPECT_FALSE(faceHeading(ObjectPoints(100, Eigen::Vector3f(NAN, NAN, NAN)), detectorBox(near, 0, 0, 0), kSensor));
}

namespace {

struct HeadingErrors {
  double heading_deg = 0, across_mps = 0;
};

// A car overtaking the ego at 25 m/s against its 22, 8-40 m ahead, weaving across its lane and the
// next (1.75 m either way, every 8 s: up to 3 deg of heading), its boxes 0.15 m and 0.04 rad off
// (the simulated detector's), scanned each frame: the RMS error of its published heading and of
// its velocity across its motion, frames 10-40.
HeadingErrors overtakingCar(bool face_heading) {
  const double w = 2 * M_PI / 8.0;
  const auto velocity = [w](double t) { return Eigen::Vector2d(25.0, 1.75 * w * std::cos(w * t)); };
  SimScene scene = oneCar(
      [=](double t) {
        const Eigen::Vector2d v = velocity(t);
        return planarPose(8.0 + 25.0 * t, 3.5 + 1.75 * std::sin(w * t), std::atan2(v.y(), v.x()), -1.73 + 0.75);
      },
      0.15);
  scene.ego = constantTwist(Pose::Identity(), 22.0, 0.0);
  scene.yaw_noise = 0.04;
  BackendConfig c;
  c.compute_covariance = false;
  c.observation_sigma_growth_per_m = 0.035;
  c.registration_types = {"Car"};
  c.face_heading = face_heading;
  SlidingWindow window(c);
  std::mt19937 rng(7);
  double sq_heading = 0, sq_across = 0;
  int n = 0;
  for (BackendInput in : scene.generate(41)) {
    const Pose truth = scene.objectTruth(1, in.frame);
    scanTheCar(scene, in, rng);
    const BackendOutput out = window.process(in);
    if (in.frame < 10) continue;
    const Eigen::Vector2d v = velocity(scene.time(in.frame)), across = Eigen::Vector2d(-v.y(), v.x()).normalized();
    for (const TrackEstimate& e : out.tracks) {
      sq_heading += std::pow(angleError(yawOf(e.pose.linear()), yawOf(truth.linear())), 2);
      sq_across += std::pow(across.dot(e.velocity.head<2>() - v), 2);
      ++n;
    }
  }
  EXPECT_GE(n, 25);
  return {std::sqrt(sq_heading / std::max(n, 1)) / kDeg, std::sqrt(sq_across / std::max(n, 1))};
}

}  // namespace

// Its boxes' headings (0.04 rad each) and positions over the 1 s window leave the chain's heading
// a few tenths of a degree off, and a car's velocity follows its heading: at 25 m/s every 0.1 deg
// is 0.04 m/s sideways. Its faces measure it to a tenth of a degree (here 0.18 -> 0.07 deg RMS,
// sideways 0.091 -> 0.075 m/s).
TEST(FaceHeading, AnOvertakingCarsHeadingAndSidewaysVelocityFromItsFaces) {
  const HeadingErrors with = overtakingCar(true), without = overtakingCar(false);
  std::printf("overtaking car: heading RMSE %.3f deg, sideways velocity %.3f m/s with its faces; "
              "%.3f deg, %.3f m/s without\n",
              with.heading_deg, with.across_mps, without.heading_deg, without.across_mps);
  EXPECT_LT(with.heading_deg, 0.5 * without.heading_deg);
  EXPECT_LT(with.across_mps, 0.9 * without.across_mps);
}
