#include "backend/line_of_sight.hpp"

#include <algorithm>
#include <cmath>

#include "dlslot/timing_stats.hpp"

namespace dlslot::backend {

std::optional<double> nearFaceRange(const ObjectPoints& points, const Eigen::Vector3d& u, double face_depth) {
  if (points.empty()) return std::nullopt;
  std::vector<double> d;
  d.reserve(points.size());
  for (const Eigen::Vector3f& p : points) d.push_back(p.cast<double>().dot(u));
  std::sort(d.begin(), d.end());
  const double limit = d[d.size() / 10] + face_depth;
  return median(std::vector<double>(d.begin(), std::upper_bound(d.begin(), d.end(), limit)));
}

bool facesTheSensor(const Box& box, double max_angle_deg) {
  const Eigen::Vector2d c = box.center.head<2>();
  if (c.norm() < 1e-6) return false;
  const double along = std::abs(std::cos(box.yaw) * c.x() + std::sin(box.yaw) * c.y()) / c.norm();
  return along >= std::cos(max_angle_deg * M_PI / 180.0);
}

std::optional<Eigen::Vector3d> lineOfSight(const ObjectPoints& points, const Eigen::Vector3d& sensor) {
  if (points.empty()) return std::nullopt;
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3f& p : points) c += p.cast<double>();
  Eigen::Vector3d u = c / static_cast<double>(points.size()) - sensor;
  u.z() = 0;
  if (u.norm() < 1e-3) return std::nullopt;
  return u.normalized();
}

}  // namespace dlslot::backend
