// The voxel of a point on a grid of cubes of side `voxel` with a corner at the origin, packed in
// one integer. One definition for the mapper's maps and the map evaluation (dlslot-eval --map),
// so both count the same cells.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>

namespace dlslot {

// 21 bits per axis: +-1048576 cells (+-210 km at 0.2 m).
inline uint64_t voxelKey(const Eigen::Vector3d& p, double voxel) {
  constexpr int64_t kOffset = 1 << 20, kMask = (1 << 21) - 1;
  const auto cell = [&](double v) { return static_cast<uint64_t>((static_cast<int64_t>(std::floor(v / voxel)) + kOffset) & kMask); };
  return (cell(p.x()) << 42) | (cell(p.y()) << 21) | cell(p.z());
}

}  // namespace dlslot
