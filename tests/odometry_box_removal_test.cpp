// Dynamic object removal (paper III-D, A-LOAM*): the points inside the scan's detected boxes,
// grown by the margin on every side but the bottom, are removed before feature extraction (the
// ground they stand on stays); A-LOAM mode keeps them.
#include <gtest/gtest.h>

#include <cmath>

#include "dlslot/box_filter.hpp"
#include "odometry/lidar_odometry.hpp"
#include "odometry_scene.hpp"

namespace dlslot::odometry {
namespace {

// A street with a car-sized block 9 m ahead, and its (slightly imprecise) detection.
struct CarScene {
  PointCloud scan;
  Box detection;
  CarScene() {
    test::Scene s = test::street();
    s.add(test::pillar({9.0, 2.0}, 0.9, -1.73, -0.3));
    scan = s.scan(Pose::Identity());
    detection.center = Eigen::Vector3d(9.05, 1.95, -1.0);
    detection.size = Eigen::Vector3d(1.8, 1.8, 1.4);
    detection.yaw = 0.02;
    detection.type = "Car";
  }
  // The scan with its detection, as the odometry node hands it over.
  Frame frame() const {
    Frame f;
    f.scan = scan;
    f.detections = {detection};
    return f;
  }
};

// A-LOAM*: detected objects' points removed.
OdometryConfig filteredConfig() {
  OdometryConfig cfg;
  cfg.remove_detected_objects = true;
  return cfg;
}

int countInside(const PointCloud& scan, const Box& b, double margin) {
  int n = 0;
  for (Eigen::Index i = 0; i < scan.cols(); ++i) n += b.contains(scan.col(i).head<3>().cast<double>(), margin) ? 1 : 0;
  return n;
}

TEST(OdometryBoxRemoval, KeepsExactlyThePointsOutsideTheBoxes) {
  const CarScene car;
  const double margin = OdometryConfig().box_margin_m;
  const std::vector<bool> inside = pointsInBoxes(car.scan, {car.detection}, margin);
  const PointCloud kept = keepOutside(car.scan, inside);
  const int n_inside = countInside(car.scan, car.detection, margin);
  ASSERT_GT(n_inside, 100);
  EXPECT_EQ(kept.cols(), car.scan.cols() - n_inside);
  EXPECT_EQ(countInside(kept, car.detection, margin), 0);
  // Order and values of the kept points are those of the scan.
  Eigen::Index j = 0;
  for (Eigen::Index i = 0; i < car.scan.cols(); ++i)
    if (!inside[i]) {
      ASSERT_TRUE(kept.col(j++) == car.scan.col(i));
    }
}

TEST(OdometryBoxRemoval, FilteredModeRemovesDetectedPointsBeforeFeatures) {
  const CarScene car;
  const OdometryConfig cfg = filteredConfig();
  LidarOdometry odometry(cfg);
  const OdometryResult r = odometry.process(car.frame(), true);
  EXPECT_TRUE(r.detections_used);
  const Box volume = removalVolume(car.detection, cfg.box_margin_m, cfg.ground_clearance_m);
  EXPECT_EQ(r.num_points_removed, countInside(car.scan, volume, 0.0));
  EXPECT_EQ(r.num_points_in, car.scan.cols());
  // Nothing of the car above its ground clearance made it into the map.
  for (const auto* layer : {&odometry.map().edges(), &odometry.map().planes()})
    for (const Eigen::Vector3f& p : layer->points()) EXPECT_FALSE(volume.contains(p.cast<double>(), 0.0));
}

TEST(OdometryBoxRemoval, RemovalVolumeIsGrownOnEverySideButTheBottom) {
  Box b;
  b.center = Eigen::Vector3d(10.0, -3.0, -1.0);
  b.size = Eigen::Vector3d(4.0, 1.8, 1.4);  // floor at z = -1.7, roof at -0.3
  b.yaw = 0.4;
  const Box v = removalVolume(b, 0.3, 0.25);
  EXPECT_DOUBLE_EQ(v.size.x(), 4.6);
  EXPECT_DOUBLE_EQ(v.size.y(), 2.4);
  EXPECT_DOUBLE_EQ(v.center.z() - 0.5 * v.size.z(), -1.45);  // floor + clearance
  EXPECT_DOUBLE_EQ(v.center.z() + 0.5 * v.size.z(), 0.0);    // roof + margin
  EXPECT_EQ(v.yaw, b.yaw);
  EXPECT_EQ(v.center.head<2>(), b.center.head<2>());
  // A negative clearance of one margin is the box grown on every side (ground removed too).
  const Box all = removalVolume(b, 0.3, -0.3);
  EXPECT_NEAR(all.size.z(), 2.0, 1e-12);
  EXPECT_NEAR(all.center.z(), -1.0, 1e-12);
  // An object lower than its clearance leaves nothing to remove.
  b.size.z() = 0.2;
  EXPECT_EQ(removalVolume(b, 0.0, 0.25).size.z(), 0.0);
  PointCloud p(4, 1);
  p.col(0) << 10.0f, -3.0f, static_cast<float>(b.center.z() + 0.1), 0.0f;  // the low box's top
  EXPECT_FALSE(objectPoints(p, {b}, 0.0, 0.25)[0]);
}

// The ground a detected car stands on is static: A-LOAM* keeps it, in the scan's features and in
// the map, while the car's body goes. Growing the box by the margin downwards as well (as
// before: ground_clearance_m = -box_margin_m) cut out the ground all around each box.
TEST(OdometryBoxRemoval, GroundAroundADetectedObjectStaysInTheMap) {
  const CarScene car;
  const double ground_z = -1.73;  // test::street()'s ground
  auto isGroundAroundCar = [&](const Eigen::Vector3d& p) {  // under the box or within its 0.3 m margin
    const Eigen::Vector3d at_box_height(p.x(), p.y(), car.detection.center.z());
    return std::abs(p.z() - ground_z) < 0.05 && car.detection.contains(at_box_height, 0.3);
  };
  int ground_points = 0;
  for (Eigen::Index i = 0; i < car.scan.cols(); ++i)
    ground_points += isGroundAroundCar(car.scan.col(i).head<3>().cast<double>());
  ASSERT_GT(ground_points, 50);  // the margin's ring around the car's footprint (152)

  const OdometryConfig cfg = filteredConfig();
  LidarOdometry odometry(cfg);
  const OdometryResult r = odometry.process(car.frame(), true);
  const std::vector<bool> removed = objectPoints(car.scan, {car.detection}, cfg.box_margin_m, cfg.ground_clearance_m);
  int ground_removed = 0, body = 0, body_removed = 0;
  for (Eigen::Index i = 0; i < car.scan.cols(); ++i) {
    const Eigen::Vector3d p = car.scan.col(i).head<3>().cast<double>();
    ground_removed += isGroundAroundCar(p) && removed[i];
    if (car.detection.contains(p, 0.0) && p.z() > -1.4) {  // the car's body, above bumper height
      ++body;
      body_removed += removed[i];
    }
  }
  EXPECT_EQ(ground_removed, 0);
  ASSERT_GT(body, 100);
  EXPECT_EQ(body_removed, body);
  // The map keeps 0.8 m voxels' centroids: a few of them lie on the ground ring around the car.
  int ground_in_map = 0;
  for (const Eigen::Vector3f& p : odometry.map().planes().points()) ground_in_map += isGroundAroundCar(p.cast<double>());
  EXPECT_GE(ground_in_map, 3);
  EXPECT_GT(r.num_points_removed, 0);
  // The box grown downwards too (the volume before): none of that ground reaches the map.
  OdometryConfig old_cfg = cfg;
  old_cfg.ground_clearance_m = -old_cfg.box_margin_m;
  LidarOdometry old_odometry(old_cfg);
  old_odometry.process(car.frame(), true);
  int old_in_map = 0;
  for (const Eigen::Vector3f& p : old_odometry.map().planes().points()) old_in_map += isGroundAroundCar(p.cast<double>());
  EXPECT_EQ(old_in_map, 0);
}

TEST(OdometryBoxRemoval, ALoamModeAndMissingDetectionsKeepEverything) {
  const CarScene car;
  const Frame frame = car.frame();

  OdometryConfig aloam;
  aloam.remove_detected_objects = false;
  LidarOdometry plain(aloam);
  const OdometryResult r1 = plain.process(frame, true);
  EXPECT_FALSE(r1.detections_used);
  EXPECT_EQ(r1.num_points_removed, 0);
  int car_points_in_map = 0;
  for (const Eigen::Vector3f& p : plain.map().planes().points())
    car_points_in_map += car.detection.contains(p.cast<double>(), 0.0) ? 1 : 0;
  EXPECT_GT(car_points_in_map, 0);

  LidarOdometry filtered;  // A-LOAM* configured, but this scan's detections never came
  const OdometryResult r2 = filtered.process(frame, false);
  EXPECT_FALSE(r2.detections_used);
  EXPECT_EQ(r2.num_points_removed, 0);
}

}  // namespace
}  // namespace dlslot::odometry
