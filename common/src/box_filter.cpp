#include "dlslot/box_filter.hpp"

#include <cmath>

namespace dlslot {

std::vector<bool> pointsInBoxes(const PointCloud& scan, const std::vector<Box>& boxes, double margin) {
  std::vector<bool> inside(scan.cols(), false);
  for (const Box& b : boxes) {
    // A cheap bounding-circle test first: most points are far from any box.
    const double r = std::hypot(0.5 * b.size.x() + margin, 0.5 * b.size.y() + margin);  // grown box's half-diagonal
    const double r2 = r * r;
    for (Eigen::Index i = 0; i < scan.cols(); ++i) {
      if (inside[i]) continue;
      const double dx = scan(0, i) - b.center.x(), dy = scan(1, i) - b.center.y();
      if (dx * dx + dy * dy > r2) continue;
      inside[i] = b.contains(scan.col(i).head<3>().cast<double>(), margin);
    }
  }
  return inside;
}

PointCloud keepOutside(const PointCloud& scan, const std::vector<bool>& inside) {
  Eigen::Index n = 0;
  for (bool in : inside) n += in ? 0 : 1;
  PointCloud out(4, n);
  Eigen::Index j = 0;
  for (Eigen::Index i = 0; i < scan.cols(); ++i)
    if (!inside[i]) out.col(j++) = scan.col(i);
  return out;
}

}  // namespace dlslot
