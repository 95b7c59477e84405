#include "mapper/scan_context.hpp"

#include <cmath>

namespace dlslot::mapper {

ScanContext makeScanContext(const PointCloud& points, const ScanContextParams& p) {
  ScanContext sc;
  sc.cells = Eigen::MatrixXf::Zero(p.rings, p.sectors);
  const double ring_m = p.max_radius_m / p.rings, sector_rad = 2 * M_PI / p.sectors;
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const double x = points(0, i), y = points(1, i), r = std::hypot(x, y);
    if (r >= p.max_radius_m || r <= 0) continue;
    double angle = std::atan2(y, x);
    if (angle < 0) angle += 2 * M_PI;
    const int ring = std::min(p.rings - 1, static_cast<int>(r / ring_m));
    const int sector = std::min(p.sectors - 1, static_cast<int>(angle / sector_rad));
    const float h = static_cast<float>(std::max(0.0, points(2, i) + p.height_offset_m));
    float& cell = sc.cells(ring, sector);
    cell = std::max(cell, h);
  }
  return sc;
}

ScanContextMatch compare(const ScanContext& a, const ScanContext& b) {
  ScanContextMatch best;
  const int sectors = static_cast<int>(a.cells.cols());
  if (a.cells.rows() != b.cells.rows() || b.cells.cols() != sectors) return best;
  const Eigen::RowVectorXf na = a.cells.colwise().norm(), nb = b.cells.colwise().norm();
  for (int shift = 0; shift < sectors; ++shift) {
    double sum = 0;
    int columns = 0;
    for (int j = 0; j < sectors; ++j) {
      const int k = (j + shift) % sectors;
      if (na(j) <= 0 || nb(k) <= 0) continue;
      sum += 1.0 - a.cells.col(j).dot(b.cells.col(k)) / (na(j) * nb(k));
      ++columns;
    }
    if (columns == 0) continue;
    const double d = sum / columns;
    if (d < best.distance) {
      best.distance = d;
      best.shift = shift;
    }
  }
  best.yaw = std::remainder(best.shift * 2 * M_PI / sectors, 2 * M_PI);
  return best;
}

}  // namespace dlslot::mapper
