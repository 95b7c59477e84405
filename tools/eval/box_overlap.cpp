#include "box_overlap.hpp"

#include <algorithm>
#include <cmath>

namespace dlslot::eval {
namespace {

double cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

double polygonArea(const std::vector<Eigen::Vector2d>& p) {
  double twice = 0.0;
  for (size_t i = 0; i < p.size(); ++i) twice += cross(p[i], p[(i + 1) % p.size()]);
  return 0.5 * std::abs(twice);
}

}  // namespace

std::vector<Eigen::Vector2d> footprint(const Box& box) {
  const double c = std::cos(box.yaw), s = std::sin(box.yaw);
  const Eigen::Vector2d along(c, s), across(-s, c), centre = box.center.head<2>();
  const double hl = 0.5 * box.size.x(), hw = 0.5 * box.size.y();
  return {centre - hl * along - hw * across, centre + hl * along - hw * across, centre + hl * along + hw * across,
          centre - hl * along + hw * across};
}

// Sutherland-Hodgman: clip `a` by each edge of the convex polygon `b` in turn.
double convexIntersectionArea(const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b) {
  std::vector<Eigen::Vector2d> out = a;
  for (size_t e = 0; e < b.size() && !out.empty(); ++e) {
    const Eigen::Vector2d p = b[e], q = b[(e + 1) % b.size()], edge = q - p;
    const auto side = [&](const Eigen::Vector2d& x) { return cross(edge, x - p); };  // >= 0: inside
    std::vector<Eigen::Vector2d> in;
    in.swap(out);
    for (size_t i = 0; i < in.size(); ++i) {
      const Eigen::Vector2d& cur = in[i];
      const Eigen::Vector2d& next = in[(i + 1) % in.size()];
      const double sc = side(cur), sn = side(next);
      if (sc >= 0) out.push_back(cur);
      if ((sc >= 0) != (sn >= 0)) out.push_back(cur + (next - cur) * (sc / (sc - sn)));
    }
  }
  return out.size() < 3 ? 0.0 : polygonArea(out);
}

double bevIntersectionArea(const Box& a, const Box& b) {
  // Boxes farther apart than their half diagonals cannot touch.
  if (bevDistance(a, b) > 0.5 * (a.size.head<2>().norm() + b.size.head<2>().norm())) return 0.0;
  return convexIntersectionArea(footprint(a), footprint(b));
}

double iou3d(const Box& a, const Box& b) {
  const double va = a.size.prod(), vb = b.size.prod();
  if (!(va > 0) || !(vb > 0)) return 0.0;
  const double z_overlap = std::min(a.center.z() + 0.5 * a.size.z(), b.center.z() + 0.5 * b.size.z()) -
                           std::max(a.center.z() - 0.5 * a.size.z(), b.center.z() - 0.5 * b.size.z());
  if (z_overlap <= 0) return 0.0;
  const double inter = bevIntersectionArea(a, b) * z_overlap;
  return inter / (va + vb - inter);
}

double bevDistance(const Box& a, const Box& b) { return (a.center.head<2>() - b.center.head<2>()).norm(); }

bool footprintContains(const Box& box, const Eigen::Vector3d& p) {
  Eigen::Vector3d q = p;
  q.z() = box.center.z();
  return box.contains(q);
}

}  // namespace dlslot::eval
