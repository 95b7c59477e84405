// dlslot-eval --map's truth on a known scene: a car passing the ego on the other carriageway,
// scanned as a spinning lidar sees it (each point where the car was when the lidar fired at it,
// on its surface give or take the range noise), beside a guard rail. A map that holds exactly the
// rail must score SA = DA = 1; with the label boxes taken at the reference instant and tight on
// the surface, the car's trailing points and half of its surface points would count as static
// structure the map lost.
#include <gtest/gtest.h>

#include <random>
#include <unordered_map>

#include "dlslot/voxel_key.hpp"
#include "map_quality.hpp"

using namespace dlslot;
using namespace dlslot::eval;

namespace {

struct Scene {
  std::vector<MapKeyframe> keyframes;
  PointCloud rail_only;  // the perfect map
  std::map<int, std::vector<Box>> labels;
};

Scene passingCar() {
  const SweepTiming sweep{0.1, true};
  const Eigen::Vector3d u(-30.0, 0, 0);  // the car relative to the lidar (closing speed), lidar frame
  Box car;
  car.size = Eigen::Vector3d(4.2, 1.8, 1.5);
  car.yaw = M_PI;
  car.id = 5;
  Scene s;
  for (int f = 0; f < 3; ++f) {  // the car's labels in scans 0, 1, 2 (lidar frames: the ego is the origin)
    Box b = car;
    b.center = Eigen::Vector3d(3.0 - 3.0 * (f - 1), 4.0, -1.0);
    s.labels[f].push_back(b);
  }
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.03);
  std::vector<Eigen::Vector3d> pts, rail;
  const Box& at1 = s.labels[1][0];
  for (double x = -2.1; x <= 2.1; x += 0.05)  // the side facing the ego, from the body's bottom to the roof
    for (double z = -0.6; z <= 0.75; z += 0.05) {
      const Eigen::Vector3d local(x, 0.9, z);  // yaw pi: the box's +y is the world's -y, the ego's side
      double t = 0;
      Eigen::Vector3d p;
      for (int it = 0; it < 5; ++it) {
        p = at1.pose() * local + t * u;
        t = sweep.firingTime(p.x(), p.y());
      }
      pts.push_back(p + p.normalized() * noise(rng));  // range noise along the ray
    }
  for (double x = -20; x <= 20; x += 0.05)
    for (double z = -1.5; z <= -0.9; z += 0.2) rail.emplace_back(x, 5.4, z);
  pts.insert(pts.end(), rail.begin(), rail.end());
  MapKeyframe k;
  k.frame = 1;
  k.scan.resize(4, static_cast<Eigen::Index>(pts.size()));
  for (size_t i = 0; i < pts.size(); ++i) k.scan.col(static_cast<Eigen::Index>(i)) << pts[i].cast<float>(), 0.5f;
  k.labels = movingLabels(s.labels, 1, 0.1);
  s.keyframes.push_back(k);
  s.rail_only.resize(4, static_cast<Eigen::Index>(rail.size()));
  for (size_t i = 0; i < rail.size(); ++i) s.rail_only.col(static_cast<Eigen::Index>(i)) << rail[i].cast<float>(), 0.5f;
  return s;
}

}  // namespace

TEST(MapTruth, LabelsMoveWithTheirTrackBetweenScans) {
  const Scene s = passingCar();
  ASSERT_EQ(s.keyframes[0].labels.size(), 1u);
  const MovingBox& m = s.keyframes[0].labels[0];
  EXPECT_NEAR(m.velocity.x(), -30.0, 1e-9);
  EXPECT_NEAR(m.velocity.y(), 0.0, 1e-9);
  EXPECT_NEAR(m.yaw_rate, 0.0, 1e-9);
  // Beside the ego (azimuth ~53 deg at its centre) the sweep saw the car ~15 ms before the reference instant.
  const SweepTiming sweep{0.1, true};
  EXPECT_NEAR(sweep.firingTime(0.0, 1.0), -0.025, 1e-12);
  EXPECT_NEAR(sweep.firingTime(-1.0, -1e-9), 0.05, 1e-6);
  EXPECT_NEAR(sweep.firingTime(1.0, 0.0), 0.0, 1e-12);
  // Its azimuth is atan2's, all around.
  for (int k = 0; k < 3600; ++k) {
    const double a = -M_PI + 2 * M_PI * k / 3600.0, r = 0.5 + k % 7;
    ASSERT_NEAR(SweepTiming::azimuth(r * std::cos(a), r * std::sin(a)), std::atan2(r * std::sin(a), r * std::cos(a)), 2.1e-4) << a;
  }
  EXPECT_EQ(SweepTiming::azimuth(0.0, 0.0), 0.0);
}

TEST(MapTruth, AMapWithoutThePassingCarScoresOneOnBothCounts) {
  const Scene s = passingCar();
  const std::set<int> moving{5};
  const MapScore score = scoreMap(s.rail_only, s.keyframes, moving, MapTruthOptions{});
  ASSERT_TRUE(score.sa && score.da);
  EXPECT_GT(score.dynamic_voxels, 100);
  EXPECT_DOUBLE_EQ(*score.sa, 1.0);
  EXPECT_DOUBLE_EQ(*score.da, 1.0);
  // The car's points judged against its box at the reference instant, tight on its surface: many
  // would be "static" structure the perfect map lost.
  MapTruthOptions old;
  old.sweep.period_s = 0;
  old.label_tolerance_m = 0;
  const MapScore naive = scoreMap(s.rail_only, s.keyframes, moving, old);
  ASSERT_TRUE(naive.sa);
  EXPECT_LT(*naive.sa, 0.95);
}

namespace {

// A wall scanned from ten keyframes 1 m apart (each keyframe's points spread over it, with range
// noise), and the map the mapper makes of it: the first point of each 0.2 m voxel, counted with
// the keyframes' poses at insertion, then moved with its keyframe by `correction` (a loop
// correction moving the keyframes, and the truth placed with the corrected poses, together).
struct Wall {
  std::vector<MapKeyframe> keyframes;
  PointCloud map;
};

Wall scannedWall(const Pose& correction, double gap_from_x = 1e9, double gap_to_x = -1e9) {
  Wall w;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> along(-15.0, 15.0), up(-1.5, 2.0);
  std::normal_distribution<double> noise(0.0, 0.02);
  std::unordered_map<uint64_t, Eigen::Vector3d> first;
  std::vector<uint64_t> order;
  for (int k = 0; k < 10; ++k) {
    MapKeyframe kf;
    kf.frame = k;
    const Pose inserted(Eigen::Translation3d(k, 0, 0));
    kf.T_grid_lidar = inserted;
    kf.T_map_lidar = correction * inserted;
    kf.scan.resize(4, 20000);
    for (Eigen::Index i = 0; i < kf.scan.cols(); ++i) {
      const Eigen::Vector3d p(along(rng), 6.05 + noise(rng), up(rng));
      kf.scan.col(i) << p.cast<float>(), 0.5f;
      const Eigen::Vector3d at_insertion = inserted * p;
      if (at_insertion.x() >= gap_from_x && at_insertion.x() < gap_to_x) continue;  // structure the map lost
      const uint64_t key = voxelKey(at_insertion, 0.2);
      if (first.emplace(key, correction * at_insertion).second) order.push_back(key);
    }
    w.keyframes.push_back(std::move(kf));
  }
  w.map.resize(4, static_cast<Eigen::Index>(order.size()));
  for (size_t i = 0; i < order.size(); ++i) w.map.col(static_cast<Eigen::Index>(i)) << first[order[i]].cast<float>(), 0.5f;
  return w;
}

}  // namespace

// Moved by half a voxel, the map holds every bit of the wall it held before. Counted on the moved
// grid (the rule before), each voxel's dense truth would spread over 4 voxels and its one map
// point land in one of them: a third of the wall "lost".
TEST(MapTruth, AMapMovedByHalfAVoxelKeepsItsStructure) {
  const std::set<int> none;
  const Wall still = scannedWall(Pose::Identity());
  const MapScore a = scoreMap(still.map, still.keyframes, none, MapTruthOptions{});
  ASSERT_TRUE(a.sa);
  EXPECT_DOUBLE_EQ(*a.sa, 1.0);
  Wall moved = scannedWall(Pose(Eigen::Translation3d(0.1, 0.1, 0.1)));
  const MapScore b = scoreMap(moved.map, moved.keyframes, none, MapTruthOptions{});
  ASSERT_TRUE(b.sa);
  EXPECT_DOUBLE_EQ(*b.sa, 1.0);
  EXPECT_EQ(b.static_voxels, a.static_voxels);
  for (MapKeyframe& k : moved.keyframes) k.T_grid_lidar.reset();  // the moved grid
  const MapScore old = scoreMap(moved.map, moved.keyframes, none, MapTruthOptions{});
  ASSERT_TRUE(old.sa);
  EXPECT_LT(*old.sa, 0.8);
}

// What the map lost stays lost, moved or not: a 2 m stretch of the 39 m of wall.
TEST(MapTruth, StructureTheMapLostStaysLost) {
  const std::set<int> none;
  for (const Pose& correction : {Pose::Identity(), Pose(Eigen::Translation3d(0.1, 0.1, 0.1))}) {
    const Wall w = scannedWall(correction, 10.0, 12.0);
    const MapScore s = scoreMap(w.map, w.keyframes, none, MapTruthOptions{});
    ASSERT_TRUE(s.sa);
    EXPECT_NEAR(*s.sa, 1.0 - 2.0 / 39.0, 0.005) << correction.translation().transpose();
  }
  MapTruthOptions coarse;
  coarse.coincidence_m = 0.1;
  EXPECT_THROW(scoreMap(PointCloud(4, 0), {}, none, coarse), std::invalid_argument);
}
