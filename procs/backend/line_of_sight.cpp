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

std::vector<bool> faceSamplesOnLine(const std::vector<double>& t, const std::vector<double>& y, double tolerance) {
  const size_t n = std::min(t.size(), y.size());
  if (n < 4) return {};
  // Siegel's repeated median: each sample's median slope to the others, then their median.
  std::vector<double> medians;
  for (size_t i = 0; i < n; ++i) {
    std::vector<double> slopes;
    for (size_t j = 0; j < n; ++j)
      if (j != i && t[j] != t[i]) slopes.push_back((y[j] - y[i]) / (t[j] - t[i]));
    if (!slopes.empty()) medians.push_back(median(slopes));
  }
  if (medians.empty()) return {};
  const double slope = median(medians);
  std::vector<double> intercepts;
  for (size_t i = 0; i < n; ++i) intercepts.push_back(y[i] - slope * t[i]);
  const double intercept = median(intercepts);
  std::vector<bool> on(n);
  size_t count = 0;
  for (size_t i = 0; i < n; ++i) count += on[i] = std::abs(y[i] - intercept - slope * t[i]) <= tolerance;
  // With half of them off, the line is the outliers' as much as the face's.
  if (2 * count <= n) on.assign(n, false);
  return on;
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
