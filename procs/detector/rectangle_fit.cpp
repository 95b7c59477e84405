#include "detector/rectangle_fit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "dlslot/types.hpp"

namespace dlslot::detector {

namespace {

struct Extent {
  float min1, max1, min2, max2;
};

Extent extentAt(const std::vector<Eigen::Vector2f>& pts, float c, float s) {
  Extent e{std::numeric_limits<float>::max(), std::numeric_limits<float>::lowest(), std::numeric_limits<float>::max(),
           std::numeric_limits<float>::lowest()};
  for (const Eigen::Vector2f& p : pts) {
    const float a = c * p.x() + s * p.y(), b = -s * p.x() + c * p.y();
    e.min1 = std::min(e.min1, a);
    e.max1 = std::max(e.max1, a);
    e.min2 = std::min(e.min2, b);
    e.max2 = std::max(e.max2, b);
  }
  return e;
}

// Zhang et al.'s closeness: sum over points of 1 / max(distance to the nearest edge, d0).
float closeness(const std::vector<Eigen::Vector2f>& pts, float theta) {
  const float c = std::cos(theta), s = std::sin(theta);
  const Extent e = extentAt(pts, c, s);
  constexpr float d0 = 0.01f;
  float sum = 0;
  for (const Eigen::Vector2f& p : pts) {
    const float a = c * p.x() + s * p.y(), b = -s * p.x() + c * p.y();
    const float d1 = std::min(e.max1 - a, a - e.min1), d2 = std::min(e.max2 - b, b - e.min2);
    sum += 1.0f / std::max(std::min(d1, d2), d0);
  }
  return sum;
}

}  // namespace

Rectangle fitRectangle(const std::vector<Eigen::Vector2f>& points, double edge_band_m) {
  // Large clusters: every k-th point is enough for the heading (the extent uses all of them).
  std::vector<Eigen::Vector2f> sample;
  const std::vector<Eigen::Vector2f>* pts = &points;
  constexpr size_t kMaxSample = 160;
  if (points.size() > kMaxSample) {
    const size_t stride = (points.size() + kMaxSample - 1) / kMaxSample;
    for (size_t i = 0; i < points.size(); i += stride) sample.push_back(points[i]);
    pts = &sample;
  }
  constexpr float kPi2 = static_cast<float>(M_PI / 2);
  const float coarse = kPi2 / 18;  // 5 degrees
  float best_theta = 0, best = -1;
  for (int k = 0; k < 18; ++k) {
    const float v = closeness(*pts, k * coarse);
    if (v > best) best = v, best_theta = k * coarse;
  }
  const float fine = coarse / 5;  // 1 degree around the best coarse heading
  const float centre = best_theta;
  for (int k = -4; k <= 4; ++k) {
    if (k == 0) continue;
    const float t = centre + k * fine;
    const float v = closeness(*pts, t);
    if (v > best) best = v, best_theta = t;
  }
  const float c = std::cos(best_theta), s = std::sin(best_theta);
  const Extent e = extentAt(points, c, s);
  Rectangle r;
  const double l1 = e.max1 - e.min1, l2 = e.max2 - e.min2;
  const Eigen::Vector2d mid1(0.5 * (e.min1 + e.max1), 0.5 * (e.min2 + e.max2));
  // Back to the lidar frame: x = c a - s b, y = s a + c b.
  r.center = Eigen::Vector2d(c * mid1.x() - s * mid1.y(), s * mid1.x() + c * mid1.y());
  double yaw = best_theta;
  if (l1 >= l2) {
    r.length = l1, r.width = l2;
  } else {
    r.length = l2, r.width = l1;
    yaw += M_PI / 2;
  }
  yaw = wrapAngle(yaw);
  if (yaw > M_PI / 2) yaw -= M_PI;
  if (yaw <= -M_PI / 2) yaw += M_PI;
  r.yaw = yaw;
  int on_edge = 0;
  const float band = static_cast<float>(edge_band_m);
  for (const Eigen::Vector2f& p : points) {
    const float a = c * p.x() + s * p.y(), b = -s * p.x() + c * p.y();
    const float d = std::min(std::min(e.max1 - a, a - e.min1), std::min(e.max2 - b, b - e.min2));
    on_edge += d <= band;
  }
  r.edge_fraction = points.empty() ? 0.0 : static_cast<double>(on_edge) / points.size();
  return r;
}

}  // namespace dlslot::detector
