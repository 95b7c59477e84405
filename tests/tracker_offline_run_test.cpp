// The tracker over a whole sequence from files (tracker::associateSequence, what dlslot-tracker
// --kitti and dlslot-track-eval run): a constructed sequence with known objects, its results rows
// checked for the class each track's history decided and for the score column.
#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <set>

#include "dlslot/kitti.hpp"
#include "offline_run.hpp"
#include "process_harness.hpp"
#include "track_evidence.hpp"

using namespace dlslot;
using namespace dlslot::tracker;
namespace fs = std::filesystem;

namespace {

// A camera 720 px focal length looking along the lidar's x axis (x_cam = -y, y_cam = -z, z_cam = x).
kitti::Calib simpleCalib() {
  kitti::Calib c;
  Eigen::Matrix4d T = Eigen::Matrix4d::Zero();
  T(0, 1) = -1;
  T(1, 2) = -1;
  T(2, 0) = 1;
  T(3, 3) = 1;
  c.T_cam_velo = Pose(T);
  for (auto& P : c.P) P << 720, 0, 620, 0, 0, 720, 175, 0, 0, 0, 1, 0;
  return c;
}

Box lidarBox(const Eigen::Vector2d& xy, const std::string& type, double score) {
  Box b;
  b.center << xy.x(), xy.y(), -0.9;
  b.size = type == "Car" ? Eigen::Vector3d(4.2, 1.8, 1.5) : Eigen::Vector3d(0.8, 0.6, 1.7);
  b.type = type;
  b.score = score;
  return b;
}

// 15 frames at 10 Hz, seen by a parked ego vehicle (its pose not the identity: speeds over ground
// are known). In the lidar frame:
//   rider:    "Pedestrian" boxes riding at 5.5 m/s (PointRCNN's pedestrian boxes on a cyclist);
//   car:      a parked car, and a more confident "Pedestrian" box inside its footprint every frame;
//   walker:   a pedestrian walking at 1.3 m/s (moves 1.8 m over the sequence);
//   standing: a pedestrian standing still, as confident as the walker.
struct Scene {
  std::string root;
  std::vector<Pose> poses;
};

Scene writeScene(const std::string& dir) {
  const kitti::Calib calib = simpleCalib();
  fs::create_directories(dir + "/training/calib");
  kitti::writeCalib(dir + "/training/calib/0000.txt", calib);
  std::vector<kitti::LabelRow> rows;
  for (int f = 0; f < 15; ++f)
    for (const Box& b : {lidarBox({10 + 0.55 * f, 2.0}, "Pedestrian", 5.0), lidarBox({15, -3}, "Car", 3.0),
                         lidarBox({15.6, -2.8}, "Pedestrian", 6.0), lidarBox({20 + 0.13 * f, 4.0}, "Pedestrian", 4.0),
                         lidarBox({25, -1}, "Pedestrian", 4.0)}) {
      kitti::LabelRow r = kitti::unprojectedRow(f, b, calib);
      r.score = b.score;
      rows.push_back(r);
    }
  kitti::writeTrackingLabels(dir + "/detections.txt", rows);
  Pose X = Pose::Identity();
  X.translation() << 100, 50, 0;
  return {dir, std::vector<Pose>(15, X)};
}

AssociatorConfig pedestrianRules() {
  AssociatorConfig cfg;
  cfg.plausibility["pedestrian"] = {3.5, "Cyclist", 0.5, true};
  cfg.classes[1].moving_evidence = 0.5;
  return cfg;
}

// Track id -> the set of types its rows carry, and its score.
struct TrackRows {
  std::set<std::string> types;
  int rows = 0;
  double score = 0;
  double x = 0;  // camera x (right) of its first row
};
std::map<int, TrackRows> byTrack(const std::vector<kitti::LabelRow>& rows) {
  std::map<int, TrackRows> out;
  for (const kitti::LabelRow& r : rows) {
    TrackRows& t = out[r.track_id];
    if (t.rows++ == 0) t.x = r.box.bottom_center.x();
    t.types.insert(r.type);
    t.score = r.score.value_or(-1);
  }
  return out;
}

}  // namespace

// The rider's track is a cyclist from its first row (the decision at 0.5 s applies to the rows
// before it too); the pedestrian box inside the car leaves no row at all (suppressed, counted with
// its rows); the walker and the standing pedestrian stay pedestrians.
TEST(TrackerOfflineRun, EachTrackIsReportedUnderTheClassItsHistoryDecided) {
  const Scene scene = writeScene(test::scratchDir());
  const kitti::SequenceReader reader(scene.root, "0000", {scene.root + "/detections.txt"});
  ASSERT_EQ(reader.size(), 15);
  const OfflineResult r = associateSequence(reader, scene.poses, pedestrianRules(), TrackOutput::All);
  EXPECT_EQ(r.class_decisions.relabelled_too_fast, 1);
  EXPECT_EQ(r.class_decisions.suppressed_on_other_class, 1);
  EXPECT_EQ(r.suppressed_rows, 15);  // every row of it, the 5 before the decision too
  const auto tracks = byTrack(r.tracks);
  ASSERT_EQ(tracks.size(), 4u);  // rider, car, walker, standing
  int cyclists = 0, pedestrians = 0, cars = 0;
  for (const auto& [id, t] : tracks) {
    ASSERT_EQ(t.types.size(), 1u) << id;
    EXPECT_EQ(t.rows, 15) << id;
    const std::string& type = *t.types.begin();
    cyclists += type == "Cyclist";
    pedestrians += type == "Pedestrian";
    cars += type == "Car";
    if (type == "Cyclist") {
      EXPECT_NEAR(t.x, -2.0, 0.01);  // the rider, at y = 2 m
    }
  }
  EXPECT_EQ(cyclists, 1);
  EXPECT_EQ(pedestrians, 2);
  EXPECT_EQ(cars, 1);
}

// The walker and the standing pedestrian have the same detections' scores; the walker moved 1.8 m
// over ground (> dynamic_displacement_m) and gains the class's moving_evidence. Tracked in the
// sensor frame (identity poses) nobody's motion over ground is known, and nothing is gained.
TEST(TrackerOfflineRun, AWalkingPedestrianOutranksAStandingOneOnlyWhenEgoPosesAreKnown) {
  const Scene scene = writeScene(test::scratchDir());
  const kitti::SequenceReader reader(scene.root, "0000", {scene.root + "/detections.txt"});
  for (const bool poses : {true, false}) {
    const std::vector<Pose> ego = poses ? scene.poses : std::vector<Pose>(15, Pose::Identity());
    const auto tracks = byTrack(associateSequence(reader, ego, pedestrianRules(), TrackOutput::All).tracks);
    double walker = 0, standing = 0;
    for (const auto& [id, t] : tracks) {
      if (std::abs(t.x + 4.0) < 0.01) walker = t.score;    // y = 4 m: camera x = -4
      if (std::abs(t.x - 1.0) < 0.01) standing = t.score;  // y = -1 m
    }
    ASSERT_NE(walker, 0) << poses;
    ASSERT_NE(standing, 0) << poses;
    if (poses) {
      EXPECT_NEAR(walker - standing, 0.5, 1e-5);
    } else {
      EXPECT_NEAR(walker, standing, 1e-5);
    }
  }
}
