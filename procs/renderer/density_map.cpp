#include "density_map.hpp"

#include <cmath>

namespace dlslot::renderer {

DensityMap::DensityMap(double cell_m, double min_z) : cell_m_(cell_m), min_z_(static_cast<float>(min_z)) {}

void DensityMap::add(const PointCloud& scan, const Pose& T_world_lidar) {
  const Eigen::Matrix<double, 2, 4> P = T_world_lidar.matrix().topRows<2>() / cell_m_;
  for (Eigen::Index i = 0; i < scan.cols(); ++i) {
    if (scan(2, i) < min_z_) continue;
    const Eigen::Vector4d p(scan(0, i), scan(1, i), scan(2, i), 1.0);
    const Eigen::Vector2d c = P * p;
    const auto ix = static_cast<int32_t>(std::floor(c.x())), iy = static_cast<int32_t>(std::floor(c.y()));
    ++cells_[(static_cast<uint64_t>(static_cast<uint32_t>(ix)) << 32) | static_cast<uint32_t>(iy)];
  }
}

}  // namespace dlslot::renderer
