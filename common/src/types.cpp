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

BoxContainment::BoxContainment(const Box& b, double margin)
    : x(b.center.x()), y(b.center.y()), z(b.center.z()), c(std::cos(b.yaw)), s(std::sin(b.yaw)),
      hx(0.5 * b.size.x() + margin), hy(0.5 * b.size.y() + margin), hz(0.5 * b.size.z() + margin),
      r2(hx * hx + hy * hy) {}

bool Box::contains(const Eigen::Vector3d& p, double margin) const {
  return BoxContainment(*this, margin).contains(p.x(), p.y(), p.z());
}

double yawOf(const Eigen::Matrix3d& R) { return std::atan2(R(1, 0), R(0, 0)); }

double wrapAngle(double a) {
  a = std::fmod(a + M_PI, 2.0 * M_PI);
  if (a <= 0) a += 2.0 * M_PI;
  return a - M_PI;
}

}  // namespace dlslot
