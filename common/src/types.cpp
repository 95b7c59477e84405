#include "dlslot/types.hpp"

#include <cmath>

namespace dlslot {

Pose Box::pose() const {
  Pose T = Pose::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = center;
  return T;
}

Box Box::transformed(const Pose& T_new_frame) const {
  Box out = *this;
  out.center = T_new_frame * center;
  // The heading after rotation; boxes stay upright (roll/pitch of the transform are ignored).
  out.yaw = yawOf(T_new_frame.linear() * pose().linear());
  return out;
}

bool Box::contains(const Eigen::Vector3d& p, double margin) const {
  const Eigen::Vector3d d = p - center;
  const double c = std::cos(yaw), s = std::sin(yaw);
  const double along = c * d.x() + s * d.y();
  const double across = -s * d.x() + c * d.y();
  return std::abs(along) <= 0.5 * size.x() + margin && std::abs(across) <= 0.5 * size.y() + margin &&
         std::abs(d.z()) <= 0.5 * size.z() + margin;
}

double yawOf(const Eigen::Matrix3d& R) { return std::atan2(R(1, 0), R(0, 0)); }

double wrapAngle(double a) {
  a = std::fmod(a + M_PI, 2.0 * M_PI);
  if (a <= 0) a += 2.0 * M_PI;
  return a - M_PI;
}

}  // namespace dlslot
