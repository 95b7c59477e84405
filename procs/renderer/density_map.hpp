// The summary image's map: how many kept scan points fell into each cell of a world-frame grid,
// with every frame placed at its estimated ego pose, so a blurred map shows pose error at a glance.
#pragma once

#include <cstdint>
#include <unordered_map>

#include "dlslot/types.hpp"

namespace dlslot::renderer {

class DensityMap {
 public:
  // cell_m: grid resolution; min_z: lidar-frame height below which points are ground and skipped.
  DensityMap(double cell_m, double min_z);

  // Adds world-frame points (x, y) from a lidar-frame scan placed at T_world_lidar.
  void add(const PointCloud& scan, const Pose& T_world_lidar);

  double cellSize() const { return cell_m_; }
  bool empty() const { return cells_.empty(); }
  // Calls f(x, y, count) for each occupied cell centre.
  template <class F>
  void forEach(F&& f) const {
    for (const auto& [key, count] : cells_) {
      const int32_t ix = static_cast<int32_t>(key >> 32), iy = static_cast<int32_t>(key & 0xffffffffu);
      f((ix + 0.5) * cell_m_, (iy + 0.5) * cell_m_, count);
    }
  }

 private:
  double cell_m_;
  float min_z_;
  std::unordered_map<uint64_t, uint32_t> cells_;
};

}  // namespace dlslot::renderer
