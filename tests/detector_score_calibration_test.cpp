// Geometric detections start tracks. The score table's known answers and errors, the
// shipped tables against the tracker's thresholds, and the two class rules measured on the
// highway's misses (a van's back is no cyclist; a far car's low back is still a car).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "detector/detector_config.hpp"
#include "detector/geometric_detector.hpp"
#include "detector/object_class.hpp"
#include "detector/score_calibration.hpp"
#include "detector_scene.hpp"
#include "tracker_config.hpp"

using namespace dlslot;
using namespace dlslot::detector;

namespace {

std::string shippedConfig() { return std::string(DLSLOT_SOURCE_DIR) + "/config/dlslot.yaml"; }

// A cluster's shape as the detector measures it: a rectangle at (x, y), ground at z = -1.73.
ClusterShape shapeAt(double x, double y, double length, double width, double yaw, double height, double bottom,
                     double profile_step, int points) {
  ClusterShape s;
  s.seen.center = Eigen::Vector2d(x, y);
  s.seen.length = length;
  s.seen.width = width;
  s.seen.yaw = yaw;
  s.seen.edge_fraction = 1.0;
  s.ground_z = -1.73;
  s.min_z = s.ground_z + bottom;
  s.max_z = s.ground_z + height;
  s.max_tan = s.max_z / std::hypot(x, y);
  s.num_points = points;
  s.profile_step = profile_step;
  return s;
}

}  // namespace

TEST(ScoreTableTest, InterpolatesBetweenKnotsAndIsConstantBeyond) {
  const ScoreTable t{{0.0, 1.0, 3.0}, {-2.0, 2.0, 3.0}};
  EXPECT_DOUBLE_EQ(t(-5.0), -2.0);
  EXPECT_DOUBLE_EQ(t(0.0), -2.0);
  EXPECT_DOUBLE_EQ(t(0.5), 0.0);
  EXPECT_DOUBLE_EQ(t(1.0), 2.0);
  EXPECT_DOUBLE_EQ(t(2.0), 2.5);
  EXPECT_DOUBLE_EQ(t(9.0), 3.0);
  const ScoreTable one{{1.0}, {4.0}};
  EXPECT_DOUBLE_EQ(one(-3.0), 4.0);
  EXPECT_DOUBLE_EQ(one(3.0), 4.0);
}

TEST(ScoreTableTest, RejectsTablesThatAreNotMonotone) {
  EXPECT_THROW((ScoreTable{{}, {}}.validate()), std::invalid_argument);
  EXPECT_THROW((ScoreTable{{0.0, 1.0}, {0.0}}.validate()), std::invalid_argument);
  EXPECT_THROW((ScoreTable{{1.0, 1.0}, {0.0, 1.0}}.validate()), std::invalid_argument);
  EXPECT_THROW((ScoreTable{{0.0, 1.0}, {2.0, 1.0}}.validate()), std::invalid_argument);
  EXPECT_NO_THROW((ScoreTable{{0.0, 1.0}, {2.0, 2.0}}.validate()));
}

TEST(ScoreCalibrationTest, EachGroupItsTableUnknownKeepsItsScore) {
  ScoreCalibration c;
  c.vehicle = {{0.0}, {5.0}};
  c.pedestrian = {{0.0}, {6.0}};
  c.cyclist = {{0.0}, {7.0}};
  EXPECT_DOUBLE_EQ(c.apply("Car", 1.0), 5.0);
  EXPECT_DOUBLE_EQ(c.apply("Van", 1.0), 5.0);
  EXPECT_DOUBLE_EQ(c.apply("Truck", 1.0), 5.0);
  EXPECT_DOUBLE_EQ(c.apply("Pedestrian", 1.0), 6.0);
  EXPECT_DOUBLE_EQ(c.apply("Cyclist", 1.0), 7.0);
  EXPECT_DOUBLE_EQ(c.apply(kUnknownType, -1.39), -1.39);
}

TEST(ScoreCalibrationTest, ShippedTablesAreTheDefaultsAndBadOnesNameTheKey) {
  ConfigSection root = loadConfig(shippedConfig());
  const DetectorConfig c = DetectorConfig::read(root.section("detector"));
  const ScoreCalibration d;
  EXPECT_EQ(c.scores.vehicle.raw, d.vehicle.raw);
  EXPECT_EQ(c.scores.vehicle.calibrated, d.vehicle.calibrated);
  EXPECT_EQ(c.scores.pedestrian.calibrated, d.pedestrian.calibrated);
  EXPECT_EQ(c.scores.cyclist.calibrated, d.cyclist.calibrated);

  std::ifstream in(shippedConfig());
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string from = "calibrated: [-0.26, 2.6, 4.71, 5.28]";
  const size_t at = text.find(from);
  ASSERT_NE(at, std::string::npos);
  text.replace(at, from.size(), "calibrated: [-0.26, 2.6, 4.71, 1.0]");
  const std::string path = testing::TempDir() + "/score_calibration_test.yaml";
  std::ofstream(path) << text;
  ConfigSection bad = loadConfig(path);
  try {
    DetectorConfig::read(bad.section("detector"));
    FAIL() << "a decreasing table was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("detector.score_calibration.vehicle"), std::string::npos) << e.what();
  }
}

// The point of the calibration: a plainly seen car and pedestrian from the geometric detector pass
// the tracker's own thresholds of the same (shipped) config, so tracks start.
TEST(ScoreCalibrationTest, PlainlySeenObjectsPassTheTrackersThresholds) {
  ConfigSection root = loadConfig(shippedConfig());
  const DetectorConfig det_cfg = DetectorConfig::read(root.section("detector"));
  const tracker::TrackerConfig trk = tracker::TrackerConfig::read(root.section("tracker"));
  auto minScore = [&](const std::string& type) {
    for (const ClassPolicy& p : trk.associator.classes)
      for (const std::string& t : p.types)
        if (t == type) return p.min_score;
    ADD_FAILURE() << "no tracker class for " << type;
    return 0.0;
  };
  test::DetectorScene scene;
  scene.car(12.0, 4.0, 0.3, 4.2, 1.75, 1.5);
  scene.place("Pedestrian", 8.0, -4.0, 0.0, 0.5, 0.6, 1.75);
  const DetectionResult r = detectObjects(scene.scan(), det_cfg);
  int cars = 0, pedestrians = 0;
  for (const Box& b : r.boxes) {
    if (b.type == "Car") {
      ++cars;
      EXPECT_GE(b.score, minScore("Car"));
    }
    if (b.type == "Pedestrian") {
      ++pedestrians;
      EXPECT_GE(b.score, minScore("Pedestrian"));
    }
  }
  EXPECT_EQ(cars, 1);
  EXPECT_EQ(pedestrians, 1);
  // With the raw scores (identity table) the car would start no track: why the table exists.
  DetectorConfig raw = det_cfg;
  raw.scores.vehicle = {{-10.0, 10.0}, {-10.0, 10.0}};
  for (const Box& b : detectObjects(scene.scan(), raw).boxes) {
    if (b.type == "Car") {
      EXPECT_LT(b.score, minScore("Car"));
    }
  }
}

TEST(DetectorClassRules, AVansLevelBackIsNoCyclistButARiderAboveWheelsIs) {
  const ClassConfig cfg;
  // A van 34 m ahead seen from behind: a 2 m wide, 0.9 m deep, level face (highway seed 1).
  const std::optional<Box> van = classifyCluster(shapeAt(34.0, 0.0, 2.0, 0.9, M_PI / 2, 1.85, 0.3, 0.0, 180), cfg);
  ASSERT_TRUE(van);
  EXPECT_TRUE(van->type == "Car" || van->type == "Van") << van->type;
  EXPECT_GT(van->center.x(), 34.0 + 1.0) << "completed away from the sensor, towards the van's centre";
  // A cyclist crossing 15 m ahead: a rider 0.8 m above the wheels' tops.
  const std::optional<Box> cyclist = classifyCluster(shapeAt(15.0, 0.0, 1.8, 0.5, M_PI / 2, 1.8, 0.0, 0.8, 60), cfg);
  ASSERT_TRUE(cyclist);
  EXPECT_EQ(cyclist->type, "Cyclist");
}

TEST(DetectorClassRules, AFarLowBackIsACarButALowRailAlongTheRaysIsNot) {
  const ClassConfig cfg;
  // A car's back 35 m ahead whose roof fell between beams: 0.85 m seen above the ground.
  const std::optional<Box> back = classifyCluster(shapeAt(35.0, 0.0, 1.7, 0.3, M_PI / 2, 0.85, 0.3, 0.0, 60), cfg);
  ASSERT_TRUE(back);
  EXPECT_EQ(back->type, "Car");
  // Near the ego the same height is too low for a car (the drop is per metre of range).
  const std::optional<Box> near = classifyCluster(shapeAt(8.0, 0.0, 1.7, 0.3, M_PI / 2, 0.85, 0.3, 0.0, 300), cfg);
  EXPECT_TRUE(!near || near->type != "Car");
  // A guard rail piece as low, 35 m out, running along the rays: not a vehicle.
  const std::optional<Box> rail = classifyCluster(shapeAt(35.0, 3.0, 2.0, 0.1, 0.05, 0.8, 0.45, 0.05, 20), cfg);
  EXPECT_TRUE(!rail || (rail->type != "Car" && rail->type != "Van"));
}

TEST(DetectorClassRules, PeopleAndCyclistsGrowToTheirPriorFootprintAboutTheirCentre) {
  const ClassConfig cfg;
  // The near half of a person 10 m ahead: 0.45 x 0.3 m seen (3-D IoU with a 0.8 x 0.6 m label < 0.25).
  const std::optional<Box> p = classifyCluster(shapeAt(10.0, 2.0, 0.45, 0.3, 0.2, 1.7, 0.0, 0.1, 80), cfg);
  ASSERT_TRUE(p);
  EXPECT_EQ(p->type, "Pedestrian");
  EXPECT_DOUBLE_EQ(p->size.x(), cfg.pedestrian_prior_length_m);
  EXPECT_DOUBLE_EQ(p->size.y(), cfg.pedestrian_prior_width_m);
  EXPECT_DOUBLE_EQ(p->center.x(), 10.0);
  EXPECT_DOUBLE_EQ(p->center.y(), 2.0);
  // A person seen larger than the prior keeps the seen size.
  const std::optional<Box> wide = classifyCluster(shapeAt(10.0, 2.0, 0.95, 0.7, 0.2, 1.7, 0.0, 0.1, 80), cfg);
  ASSERT_TRUE(wide);
  EXPECT_EQ(wide->type, "Pedestrian");
  EXPECT_DOUBLE_EQ(wide->size.x(), 0.95);
  EXPECT_DOUBLE_EQ(wide->size.y(), 0.7);
  // A cyclist's side: completed to the cyclist prior's width.
  const std::optional<Box> c = classifyCluster(shapeAt(15.0, 0.0, 1.8, 0.3, M_PI / 2, 1.8, 0.0, 0.8, 60), cfg);
  ASSERT_TRUE(c);
  EXPECT_EQ(c->type, "Cyclist");
  EXPECT_DOUBLE_EQ(c->size.x(), 1.8);
  EXPECT_DOUBLE_EQ(c->size.y(), cfg.cyclist_prior_width_m);
}
