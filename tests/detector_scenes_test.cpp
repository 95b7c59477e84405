// The geometric detector on ray-cast scenes with known boxes: flat ground, a slope, a kerb, a row
// of parked cars, a pedestrian next to a pole, a truck beside the ego, a van seen over a car, a
// person seen over a parked car; and bad input (empty scan, NaN points).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>

#include "detector/geometric_detector.hpp"
#include "detector_scene.hpp"

using namespace dlslot;
using namespace dlslot::detector;
using dlslot::test::DetectorScene;

namespace {

bool isVehicle(const std::string& t) { return t == "Car" || t == "Van" || t == "Truck"; }

// The detection nearest to `truth` in bird's-eye view, or nullptr when none is within 1 m.
const Box* nearest(const std::vector<Box>& dets, const Box& truth, double within = 1.0) {
  const Box* best = nullptr;
  double best_d = within;
  for (const Box& d : dets) {
    const double dist = (d.center - truth.center).head<2>().norm();
    if (dist < best_d) best_d = dist, best = &d;
  }
  return best;
}

// Yaw difference modulo pi (a box's heading is ambiguous by half a turn).
double axisError(double a, double b) {
  const double d = std::fmod(std::abs(a - b), M_PI);
  return std::min(d, M_PI - d);
}

int countOf(const std::vector<Box>& dets, const std::string& type) {
  int n = 0;
  for (const Box& d : dets) n += d.type == type;
  return n;
}

// The boxes, one a line, for failure messages.
std::string describe(const DetectionResult& r) {
  std::string out;
  char buf[200];
  for (const Box& d : r.boxes) {
    std::snprintf(buf, sizeof buf, "  %s at (%.2f, %.2f, %.2f) size %.2f x %.2f x %.2f yaw %.2f score %.2f\n",
                  d.type.c_str(), d.center.x(), d.center.y(), d.center.z(), d.size.x(), d.size.y(), d.size.z(), d.yaw,
                  d.score);
    out += buf;
  }
  return out;
}

}  // namespace

TEST(DetectorScenes, CarOnFlatGroundGetsItsBoxHeadingAndClass) {
  DetectorScene scene;
  const Box truth = scene.car(12.0, 4.0, 0.3, 4.2, 1.75, 1.5);
  const DetectionResult r = detectObjects(scene.scan(), DetectorConfig{});
  SCOPED_TRACE("detections:\n" + describe(r));
  ASSERT_EQ(r.boxes.size(), 1u) << "only the car stands on flat ground";
  const Box& d = r.boxes[0];
  EXPECT_EQ(d.type, "Car");
  EXPECT_LT((d.center - truth.center).head<2>().norm(), 0.4);
  EXPECT_LT(axisError(d.yaw, truth.yaw), 3.0 * M_PI / 180);
  EXPECT_NEAR(d.size.x(), 4.2, 0.3);
  EXPECT_NEAR(d.size.y(), 1.75, 0.3);
  EXPECT_NEAR(d.size.z(), 1.5, 0.15);
  EXPECT_NEAR(d.center.z(), truth.center.z(), 0.15);
  EXPECT_GT(d.score, 0.0);
}

TEST(DetectorScenes, SlopeIsGroundAndCarsOnItAreFound) {
  // 6 % uphill ahead: one plane through the sensor's ground would call the far slope an obstacle.
  // The cars' roofs are above the top beam there, so their seen height is a lower bound.
  DetectorScene scene;
  scene.slope = 0.06;
  const Box near_car = scene.car(13.0, -3.5, 0.0, 4.3, 1.8, 1.5);
  const Box far_car = scene.car(24.0, 3.5, 0.05, 4.0, 1.7, 1.45);
  const DetectionResult r = detectObjects(scene.scan(), DetectorConfig{});
  SCOPED_TRACE("detections:\n" + describe(r));
  // Nothing classified but the two cars. (The far car's body and cabin faces are a metre apart with
  // its roof above the sensor's view: the body's back may stay an Unknown piece, which only
  // removes points.)
  EXPECT_EQ(static_cast<int>(r.boxes.size()) - countOf(r.boxes, kUnknownType), 2);
  EXPECT_EQ(countOf(r.boxes, "Car"), 2);
  for (const Box& truth : {near_car, far_car}) {
    const Box* d = nearest(r.boxes, truth);
    ASSERT_NE(d, nullptr) << "car at x " << truth.center.x();
    EXPECT_EQ(d->type, "Car");
    EXPECT_NEAR(d->center.z() - 0.5 * d->size.z(), truth.center.z() - 0.5 * truth.size.z(), 0.15)
        << "box on the sloped ground";
  }
  // Ground points on the slope are not obstacles: all obstacle points belong to the cars.
  EXPECT_LT(r.obstacle_points, 4000);
}

TEST(DetectorScenes, KerbIsGroundAndPedestrianOnThePavementIsFound) {
  DetectorScene scene;
  scene.kerb_y = 4.0;  // the pavement left of the road, 15 cm up
  scene.kerb_height = 0.15;
  const Box person = scene.place("Pedestrian", 10.0, 6.0, 0.0, 0.6, 0.5, 1.75);
  const Box car = scene.car(14.0, -3.5, 0.0, 4.2, 1.75, 1.5);
  const DetectionResult r = detectObjects(scene.scan(), DetectorConfig{});
  SCOPED_TRACE("detections:\n" + describe(r));
  EXPECT_EQ(r.boxes.size(), 2u) << "the kerb itself is no object";
  const Box* p = nearest(r.boxes, person, 0.5);
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(p->type, "Pedestrian");
  EXPECT_NEAR(p->size.z(), 1.75, 0.2);
  const Box* c = nearest(r.boxes, car);
  ASSERT_NE(c, nullptr);
  EXPECT_EQ(c->type, "Car");
}

TEST(DetectorScenes, RowOfParkedCarsGivesOneCarEach) {
  // Parked nose to tail 1.2 m apart along the road's edge: each its own cluster and box, and the
  // partly hidden ones are completed to a car's size. (A fifth car behind them, 28 m ahead, shows
  // only its side at 7 deg to the rays: one point a column 0.7 m apart, too sparse to join up.)
  DetectorScene scene;
  std::vector<Box> parked;
  for (int k = 0; k < 4; ++k) parked.push_back(scene.car(6.0 + 5.4 * k, -4.5, 0.0, 4.2, 1.75, 1.5));
  const DetectionResult r = detectObjects(scene.scan(), DetectorConfig{});
  SCOPED_TRACE("detections:\n" + describe(r));
  int found = 0;
  for (const Box& truth : parked) {
    const Box* d = nearest(r.boxes, truth, 1.0);
    if (d && isVehicle(d->type)) {
      ++found;
      EXPECT_LT(axisError(d->yaw, 0.0), 5.0 * M_PI / 180) << "car at x " << truth.center.x();
      EXPECT_GT(d->size.x(), 3.5) << "completed to a car's length";
    }
  }
  EXPECT_EQ(found, 4);
  EXPECT_EQ(countOf(r.boxes, "Car") + countOf(r.boxes, "Van"), 4) << "no car split in two";
}

TEST(DetectorScenes, PedestrianNextToAPoleIsFoundAndThePoleIsNot) {
  DetectorScene scene;
  const Box person = scene.place("Pedestrian", 9.0, 2.0, 0.4, 0.7, 0.55, 1.7);
  scene.pole(9.0, 3.1, 0.12, 5.0);  // a lamp post 1.1 m from the person's centre
  const DetectionResult r = detectObjects(scene.scan(), DetectorConfig{});
  SCOPED_TRACE("detections:\n" + describe(r));
  const Box* p = nearest(r.boxes, person, 0.4);
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(p->type, "Pedestrian");
  EXPECT_LT(p->size.x(), 1.0) << "not merged with the pole";
  EXPECT_EQ(r.boxes.size(), 1u) << "the pole is background";
}

TEST(DetectorScenes, WallAndPoleAloneGiveNoObjects) {
  DetectorScene scene;
  scene.place("Wall", 20.0, 8.0, 0.0, 30.0, 0.3, 3.0);  // a building's wall along the road
  scene.pole(8.0, -4.0, 0.15, 6.0);
  const DetectionResult r = detectObjects(scene.scan(), DetectorConfig{});
  SCOPED_TRACE("detections:\n" + describe(r));
  for (const Box& d : r.boxes) EXPECT_EQ(d.type, kUnknownType) << "at " << d.center.transpose();
  EXPECT_EQ(r.boxes.size(), 0u);
}

TEST(DetectorScenes, TruckBesideTheEgoIsOneTruck) {
  // A 10 m truck in the next lane, level with the ego: the top beam cuts its side at ~1.85 m, and
  // the points nearer than min_range_m (the ego's own body) cut the side in two pieces.
  DetectorScene scene;
  const Box truck = scene.place("Truck", 1.0, -3.5, 0.0, 10.0, 2.5, 3.2);
  const DetectionResult r = detectObjects(scene.scan(), DetectorConfig{});
  SCOPED_TRACE("detections:\n" + describe(r));
  const Box* d = nearest(r.boxes, truck, 1.0);
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(d->type, "Truck");
  EXPECT_NEAR(d->size.x(), 10.0, 0.5);
  EXPECT_LT(axisError(d->yaw, 0.0), 3.0 * M_PI / 180);
  EXPECT_GE(d->size.z(), 2.5) << "at least a truck's height, not the 1.85 m the top beam saw";
  EXPECT_EQ(r.boxes.size(), 1u) << "not split in two";
}

TEST(DetectorScenes, VanSeenOverACarIsAVehicleAndASignIsNot) {
  // A van queueing 3 m behind a car ahead shows only its top above the car: it seems to hang in
  // the air, but its bottom is hidden by the car, not raised. A sign 2.5 m up beyond it is not hidden.
  DetectorScene scene;
  scene.car(15.0, 0.0, 0.0, 4.2, 1.75, 1.5);
  const Box van = scene.place("Van", 22.5, 0.0, 0.0, 5.0, 1.95, 2.3);
  Box& sign = scene.place("Sign", 32.0, 0.0, 0.0, 0.3, 2.0, 1.0);
  sign.center.z() += 2.5;
  const Box sign_box = sign;
  const DetectionResult r = detectObjects(scene.scan(), DetectorConfig{});
  SCOPED_TRACE("detections:\n" + describe(r));
  const Box* d = nearest(r.boxes, van, 1.0);
  ASSERT_NE(d, nullptr);
  EXPECT_TRUE(isVehicle(d->type)) << d->type;
  EXPECT_NEAR(d->center.z() - 0.5 * d->size.z(), van.center.z() - 0.5 * van.size.z(), 0.2) << "standing on the ground";
  EXPECT_EQ(nearest(r.boxes, sign_box, 2.0), nullptr) << "the sign is an overhang";
}

TEST(DetectorScenes, GroundDoesNotClimbAPersonSeenOverAParkedCar) {
  // A parked car hides the pavement behind it for tens of metres; of a person standing there only
  // the top half shows over its roof. The ground line must not climb onto that half across the
  // hidden stretch (the slope allowed over a gap is capped: kMaxClimbRun_m), or the person becomes
  // a sliver too short to be one.
  DetectorScene scene;
  scene.car(12.5, -4.6, 0.0, 4.2, 1.75, 1.3);
  const Box person = scene.place("Pedestrian", 20.5, -6.5, 0.0, 0.6, 0.5, 1.75);
  const DetectionResult r = detectObjects(scene.scan(), DetectorConfig{});
  SCOPED_TRACE("detections:\n" + describe(r));
  const Box* p = nearest(r.boxes, person, 0.6);
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(p->type, "Pedestrian");
  EXPECT_NEAR(p->size.z(), 1.75, 0.2) << "standing on the road, not on the ground line's climb";
}

TEST(DetectorBadInput, EmptyScanGivesNoBoxes) {
  const DetectionResult r = detectObjects(PointCloud(4, 0), DetectorConfig{});
  EXPECT_TRUE(r.boxes.empty());
  EXPECT_EQ(r.points_used, 0);
}

TEST(DetectorBadInput, NaNAndInfinitePointsAreSkipped) {
  DetectorScene scene;
  scene.car(12.0, 4.0, 0.3, 4.2, 1.75, 1.5);
  const PointCloud clean = scene.scan();
  PointCloud dirty(4, clean.cols() + 300);
  dirty.leftCols(clean.cols()) = clean;
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  for (int k = 0; k < 300; ++k) dirty.col(clean.cols() + k) << (k % 3 == 0 ? nan : 5.0f), (k % 3 == 1 ? inf : 1.0f),
                                                                 (k % 3 == 2 ? nan : 0.0f), 0.5f;
  const DetectionResult a = detectObjects(clean, DetectorConfig{}), b = detectObjects(dirty, DetectorConfig{});
  EXPECT_EQ(b.points_used, a.points_used);
  ASSERT_EQ(b.boxes.size(), a.boxes.size());
  for (size_t k = 0; k < a.boxes.size(); ++k) EXPECT_TRUE(b.boxes[k].center.isApprox(a.boxes[k].center));
}
