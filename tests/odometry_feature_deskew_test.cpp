// The odometry's de-skewing of a scan's features (feature_deskew.hpp), with known answers: the
// sweep's motion keeps the vehicle's planar velocity and yaw rate and drops the body's ride (heave,
// roll and pitch rates), and the features of a wall scanned from a moving, turning vehicle land back on the wall.
#include <gtest/gtest.h>

#include "odometry/feature_deskew.hpp"
#include "sweep_scene.hpp"

using namespace dlslot;
using namespace dlslot::odometry;
using namespace dlslot::test;

namespace {

// The scan's points split round-robin over the four feature clouds, as extraction would keep them.
ScanFeatures featuresOf(const PointCloud& scan) {
  ScanFeatures f;
  FeatureCloud* clouds[] = {&f.sharp, &f.less_sharp, &f.flat, &f.less_flat};
  for (Eigen::Index i = 0; i < scan.cols(); ++i) {
    pcl::PointXYZI p;
    p.getVector3fMap() = scan.col(i).head<3>();
    p.intensity = scan(3, i);
    clouds[i % 4]->push_back(p);
  }
  return f;
}

double worstOffWall(const ScanFeatures& f, const Pose& T0, double radius) {
  double worst = 0;
  for (const FeatureCloud* c : {&f.sharp, &f.less_sharp, &f.flat, &f.less_flat})
    for (const pcl::PointXYZI& p : c->points)
      worst = std::max(worst, std::abs((T0 * p.getVector3fMap().cast<double>()).head<2>().norm() - radius));
  return worst;
}

}  // namespace

TEST(OdometryFeatureDeskew, TheSweepsMotionIsTheVehiclesPlanarMotionNotItsRide) {
  BodyTwist motion = twist(12.0, 0.3, 0.4, 0.08);
  motion.angular.x() = -0.05;  // rolling too
  motion.velocity.z() = 0.1;
  const BodyTwist kept = vehicleTwist(motion.at(0.1), 0.1);  // last frame's T_prev_cur, 0.1 s a scan
  EXPECT_NEAR((kept.velocity.head<2>() - motion.velocity.head<2>()).norm(), 0.0, 1e-9);
  EXPECT_EQ(kept.velocity.z(), 0.0);
  EXPECT_NEAR(kept.angular.z(), 0.4, 1e-9);
  EXPECT_EQ(kept.angular.x(), 0.0);
  EXPECT_EQ(kept.angular.y(), 0.0);
}

TEST(OdometryFeatureDeskew, AWallScannedFromAMovingTurningVehicleLandsBackOnTheWall) {
  const SweepTiming sweep{0.1, true};
  const double radius = 20.0;
  const Pose T0 = lidarStart();
  const BodyTwist motion = twist(15.0, 0.2, 0.5);  // 15 m/s, turning at 0.5 rad/s
  ScanFeatures f = featuresOf(skewedScanOfCylinder(T0, motion, sweep, radius));
  const double skewed = worstOffWall(f, T0, radius);
  EXPECT_GT(skewed, 0.5);  // split by 1.5 m of travel, bent by 2.9 deg of turn
  // The previous frame's motion, as the odometry keeps it: the same constant twist.
  deskewFeatures(f, sweep, vehicleTwist(motion.at(0.1), sweep.period_s));
  EXPECT_LT(worstOffWall(f, T0, radius), 0.003) << "as fired: " << skewed << " m off the wall";
}

TEST(OdometryFeatureDeskew, DeskewedScansStayAsTheyAre) {
  const Pose T0 = lidarStart();
  const PointCloud scan = skewedScanOfCylinder(T0, twist(15.0, 0.0, 0.5), SweepTiming{0.1, true}, 20.0);
  ScanFeatures f = featuresOf(scan);
  deskewFeatures(f, SweepTiming{0.0, true}, twist(15.0, 0.0, 0.5));  // period 0: de-skewed data
  EXPECT_EQ(worstOffWall(f, T0, 20.0), worstOffWall(featuresOf(scan), T0, 20.0));
}
