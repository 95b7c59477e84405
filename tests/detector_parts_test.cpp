// The detector's pieces with known answers: the fast atan2, the L-shape rectangle fit, the
// completion of partly seen vehicles, the per-sector ground on a kerb, the evaluation's matching,
// the config section, and the tracker's refusal to track the Unknown type.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>

#include "detector/detection_eval.hpp"
#include "detector/detector_config.hpp"
#include "detector/object_class.hpp"
#include "detector/rectangle_fit.hpp"
#include "detector/scan_layout.hpp"
#include "dlslot/track_lifecycle.hpp"
#include "trajectory_associator.hpp"

using namespace dlslot;
using namespace dlslot::detector;

namespace {

std::string shippedConfig() { return std::string(DLSLOT_SOURCE_DIR) + "/config/dlslot.yaml"; }

// Points along the two seen sides of a rectangle (centre c, size l x w, yaw), every 5 cm, with
// noise: the sides facing the origin.
std::vector<Eigen::Vector2f> lShape(const Eigen::Vector2d& c, double l, double w, double yaw, double noise) {
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0.0, noise);
  const Eigen::Vector2d u(std::cos(yaw), std::sin(yaw)), v(-u.y(), u.x());
  // The corner nearest the origin, and the two sides from it.
  Eigen::Vector2d corner = c - 0.5 * l * u - 0.5 * w * v;
  for (int a : {-1, 1})
    for (int b : {-1, 1}) {
      const Eigen::Vector2d p = c + a * 0.5 * l * u + b * 0.5 * w * v;
      if (p.norm() < corner.norm()) corner = p;
    }
  const Eigen::Vector2d along = (c - corner).dot(u) > 0 ? u : Eigen::Vector2d(-u), across = (c - corner).dot(v) > 0 ? v : Eigen::Vector2d(-v);
  std::vector<Eigen::Vector2f> pts;
  for (double s = 0; s <= l; s += 0.05) pts.push_back((corner + s * along + n(rng) * across).cast<float>());
  for (double s = 0.05; s <= w; s += 0.05) pts.push_back((corner + s * across + n(rng) * along).cast<float>());
  return pts;
}

double axisError(double a, double b) {
  const double d = std::fmod(std::abs(a - b), M_PI);
  return std::min(d, M_PI - d);
}

Box box(const std::string& type, double x, double y) {
  Box b;
  b.type = type;
  b.center = Eigen::Vector3d(x, y, -1);
  b.size = Eigen::Vector3d(4, 1.8, 1.5);
  return b;
}

}  // namespace

TEST(DetectorParts, FastAtan2MatchesTheLibrary) {
  double worst = 0;
  for (int i = 0; i < 3600; ++i) {
    const double a = -M_PI + 2 * M_PI * i / 3600.0;
    for (const double r : {0.5, 7.0, 80.0}) {
      const float x = static_cast<float>(r * std::cos(a)), y = static_cast<float>(r * std::sin(a));
      worst = std::max(worst, static_cast<double>(std::abs(fastAtan2(y, x) - std::atan2(y, x))));
    }
  }
  EXPECT_LT(worst, 2e-5);
  EXPECT_EQ(fastAtan2(0.0f, 0.0f), 0.0f);
}

TEST(DetectorParts, LShapeFitRecoversHeadingAndSize) {
  for (const double yaw : {0.0, 0.35, -0.8, 1.2}) {
    const std::vector<Eigen::Vector2f> pts = lShape({15, -4}, 4.4, 1.8, yaw, 0.02);
    const Rectangle r = fitRectangle(pts);
    EXPECT_LT(axisError(r.yaw, yaw), 2.0 * M_PI / 180) << "yaw " << yaw;
    EXPECT_NEAR(r.length, 4.4, 0.1);
    EXPECT_NEAR(r.width, 1.8, 0.1);
    EXPECT_LT((r.center - Eigen::Vector2d(15, -4)).norm(), 0.1);
    EXPECT_GT(r.edge_fraction, 0.95);
    EXPECT_GT(r.yaw, -M_PI / 2 - 1e-9);
    EXPECT_LE(r.yaw, M_PI / 2 + 1e-9);
  }
}

TEST(DetectorParts, BackOfACarIsCompletedAwayFromTheSensor) {
  // Only the back of a car 12 m ahead is seen: 1.7 m across the line of sight, a few cm deep.
  Rectangle back;
  back.center = Eigen::Vector2d(12.0, 0.0);
  back.length = 1.7;
  back.width = 0.1;
  back.yaw = M_PI / 2;
  const Rectangle full = completeVehicle(back, 4.2, 1.75, 2.3);
  EXPECT_LT(axisError(full.yaw, 0.0), 1e-9) << "the car runs along the line of sight";
  EXPECT_NEAR(full.length, 4.2, 1e-9);
  EXPECT_NEAR(full.width, 1.75, 1e-9);
  EXPECT_NEAR(full.center.x(), 11.95 + 2.1, 1e-9) << "grown away from the sensor, the back face kept";
  EXPECT_NEAR(full.center.y(), 0.0, 0.03);
}

TEST(DetectorParts, SideOfACarIsWidenedAwayFromTheSensor) {
  Rectangle side;  // the right side of a car 4 m to the left: 4.3 m along x, thin
  side.center = Eigen::Vector2d(10.0, 4.0);
  side.length = 4.3;
  side.width = 0.15;
  side.yaw = 0.0;
  const Rectangle full = completeVehicle(side, 4.2, 1.75, 2.3);
  EXPECT_NEAR(full.length, 4.3, 1e-9);
  EXPECT_NEAR(full.width, 1.75, 1e-9);
  EXPECT_NEAR(full.center.y(), 4.0 + 0.5 * (1.75 - 0.15), 1e-9);
  EXPECT_NEAR(full.center.x(), 10.0, 1e-9);
}

TEST(DetectorParts, PolesAndOverhangsAreBackgroundUnknownsAreMarked) {
  ClassConfig cfg;
  ClusterShape pole;
  pole.seen.length = 0.2;
  pole.seen.width = 0.2;
  pole.seen.center = Eigen::Vector2d(8, 2);
  pole.ground_z = -1.73;
  pole.min_z = -1.4;
  pole.max_z = 0.28;  // up to the top beam at 8 m
  pole.max_tan = 0.035;
  pole.num_points = 80;
  EXPECT_FALSE(classifyCluster(pole, cfg).has_value());
  ClusterShape canopy = pole;
  canopy.seen.length = canopy.seen.width = 2.0;
  canopy.min_z = -0.2;  // 1.5 m above the ground
  EXPECT_FALSE(classifyCluster(canopy, cfg).has_value());
  ClusterShape bin = pole;  // a 1.5 m x 1.4 m box 1.3 m tall: no class, but object-sized
  bin.seen.length = 1.5;
  bin.seen.width = 1.4;
  bin.max_z = -0.43;
  bin.max_tan = -0.08;
  const std::optional<Box> b = classifyCluster(bin, cfg);
  ASSERT_TRUE(b.has_value());
  EXPECT_EQ(b->type, kUnknownType);
}

TEST(DetectorParts, MatchingIsOneToOneWithinTheDistanceAndRange) {
  const EvalClass car = defaultEvalClasses()[0];
  const std::vector<Box> labels = {box("Car", 10, 0), box("Van", 20, 3), box("Car", 45, 0), box("Pedestrian", 5, 5)};
  // Two detections near the first car (one counts, one is a false positive), a Truck on the Van
  // (same class group), one too far from anything, one beyond the range.
  const std::vector<Box> dets = {box("Car", 10.5, 0.2), box("Car", 11.0, -0.5), box("Truck", 21.5, 3.5),
                                 box("Car", 30, -8), box("Car", 44, 0)};
  const MatchCounts m = matchFrame(labels, dets, car, EvalOptions{});
  EXPECT_EQ(m.labels, 2);       // the car at 45 m is out of range, the pedestrian another class
  EXPECT_EQ(m.detections, 4);   // the one at 44 m is out of range
  EXPECT_EQ(m.matched, 2);
  EXPECT_DOUBLE_EQ(m.recall(), 1.0);
  EXPECT_DOUBLE_EQ(m.precision(), 0.5);
  // An ignore region takes the unmatched detection at (30, -8) out of the count.
  const MatchCounts ig = matchFrame(labels, dets, car, EvalOptions{}, [](const Box& b) { return b.center.x() == 30; });
  EXPECT_EQ(ig.ignored, 1);
  EXPECT_EQ(ig.detections, 3);
}

TEST(DetectorConfigTest, ShippedSectionMatchesTheDefaults) {
  ConfigSection root = loadConfig(shippedConfig());
  const DetectorConfig c = DetectorConfig::read(root.section("detector"));
  const DetectorConfig d;
  EXPECT_EQ(c.ground.sectors, d.ground.sectors);
  EXPECT_DOUBLE_EQ(c.ground.max_step_m, d.ground.max_step_m);
  EXPECT_EQ(c.clustering.columns, d.clustering.columns);
  EXPECT_DOUBLE_EQ(c.clustering.distance_per_m, d.clustering.distance_per_m);
  EXPECT_DOUBLE_EQ(c.classes.car.max_length_m, d.classes.car.max_length_m);
  EXPECT_DOUBLE_EQ(c.classes.pedestrian.min_height_m, d.classes.pedestrian.min_height_m);
  EXPECT_DOUBLE_EQ(c.classes.min_corner_edge_fraction, d.classes.min_corner_edge_fraction);
  EXPECT_NEAR(c.classes.top_tan, d.classes.top_tan, 1e-3);
}

TEST(DetectorConfigTest, UnknownAndBadKeysNameTheKey) {
  std::ifstream in(shippedConfig());
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto errorWith = [&](const std::string& from, const std::string& to) {
    std::string t = text;
    const size_t at = t.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    t.replace(at, from.size(), to);
    const std::string path = testing::TempDir() + "/detector_config_test.yaml";
    std::ofstream(path) << t;
    try {
      ConfigSection root = loadConfig(path);
      DetectorConfig::read(root.section("detector"));
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(errorWith("    sectors: 360", "    sector: 360").find("detector.ground.sectors"), std::string::npos);
  EXPECT_NE(errorWith("    columns: 2048", "    columns: 10").find("clustering.columns"), std::string::npos);
  EXPECT_NE(errorWith("car: {length_m: [3.2, 5.4]", "car: {length_m: [5.4, 3.2]").find("car.length_m"),
            std::string::npos);
}

TEST(DetectorUnknownType, TrackerClassesRefuseIt) {
  ClassPolicy p;
  p.name = "car";
  p.types = {"Car", kUnknownType};
  try {
    p.validate();
    FAIL() << "a tracker class holding the Unknown type was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("never tracked"), std::string::npos) << e.what();
  }
}

TEST(DetectorUnknownType, TrackerNeverTracksUnknownBoxesHoweverConfident) {
  // The same confident box at the same place for ten frames: a car becomes a track, an Unknown never.
  tracker::TrajectoryAssociator a(tracker::AssociatorConfig{});
  int car_tracks = 0, unknown_associations = 0, unknown_skipped = 0;
  for (int f = 0; f < 10; ++f) {
    Box car = box("Car", 12, 3), unknown = box(kUnknownType, 20, -5);
    car.score = unknown.score = 9.0;
    const tracker::FrameAssociations r = a.associate(f, 0.1 * f, Pose::Identity(), {car, unknown});
    for (const tracker::Association& as : r.associations) {
      if (as.detection_index == 1) ++unknown_associations;
      if (as.detection_index == 0 && as.new_track) ++car_tracks;
    }
    unknown_skipped += r.skipped.untracked_type;
  }
  EXPECT_EQ(car_tracks, 1);
  EXPECT_EQ(unknown_associations, 0);
  EXPECT_EQ(unknown_skipped, 10);
}
