// Dynamic object removal (paper III-D, A-LOAM*): the points inside the scan's detected boxes,
// grown by the margin, are removed before feature extraction; A-LOAM mode keeps them.
#include <gtest/gtest.h>

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
};

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
  OdometryConfig cfg;
  cfg.remove_detected_objects = true;
  LidarOdometry odometry(cfg);
  Frame frame;
  frame.scan = car.scan;
  frame.detections = {car.detection};
  const OdometryResult r = odometry.process(frame, true);
  EXPECT_TRUE(r.detections_used);
  EXPECT_EQ(r.num_points_removed, countInside(car.scan, car.detection, cfg.box_margin_m));
  EXPECT_EQ(r.num_points_in, car.scan.cols());
  // Nothing of the car made it into the map.
  for (const auto* layer : {&odometry.map().edges(), &odometry.map().planes()})
    for (const Eigen::Vector3f& p : layer->points()) EXPECT_FALSE(car.detection.contains(p.cast<double>(), 0.0));
}

TEST(OdometryBoxRemoval, ALoamModeAndMissingDetectionsKeepEverything) {
  const CarScene car;
  Frame frame;
  frame.scan = car.scan;
  frame.detections = {car.detection};

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
