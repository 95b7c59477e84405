#include "feature_deskew.hpp"

#include <cmath>

#include "dlslot/vertical_angle.hpp"

namespace dlslot::odometry {

BodyTwist vehicleTwist(const Pose& per_frame, double period_s) {
  BodyTwist twist = twistBetween(Pose::Identity(), per_frame, period_s);
  twist.velocity.z() = 0.0;           // the ride's heave
  twist.angular.head<2>().setZero();  // the ride's roll and pitch rates
  return twist;
}

void deskewFeatures(ScanFeatures& features, const SweepTiming& sweep, const BodyTwist& twist) {
  if (sweep.period_s <= 0) return;
  const SweepMotion motion(sweep, twist);
  for (FeatureCloud* cloud : {&features.sharp, &features.less_sharp, &features.flat, &features.less_flat})
    for (pcl::PointXYZI& p : cloud->points) p.getVector3fMap() = motion.toReference(p.getVector3fMap());
}

void correctElevation(ScanFeatures& features, double angle_rad) {
  if (angle_rad == 0) return;
  const float c = static_cast<float>(std::cos(angle_rad)), s = static_cast<float>(std::sin(angle_rad));
  for (FeatureCloud* cloud : {&features.sharp, &features.less_sharp, &features.flat, &features.less_flat})
    for (pcl::PointXYZI& p : cloud->points) raiseElevation(p.x, p.y, p.z, c, s);
}

}  // namespace dlslot::odometry
