#include "mapper/voxel_map.hpp"

#include <cmath>
#include <stdexcept>

namespace dlslot::mapper {

int32_t& VoxelMap::slot(int64_t cx, int64_t cy, int64_t cz) {
  // Block coordinates: an arithmetic shift is a floor division, so negative cells go to the right block.
  constexpr int64_t kOffset = 1 << 20, kMask = (1 << 21) - 1;
  const auto pack = [](int64_t b) { return static_cast<uint64_t>((b + kOffset) & kMask); };
  const uint64_t key = (pack(cx >> kBlockBits) << 42) | (pack(cy >> kBlockBits) << 21) | pack(cz >> kBlockBits);
  if (key != last_key_) {
    auto [it, inserted] = block_index_.try_emplace(key, static_cast<int32_t>(blocks_.size()));
    if (inserted) blocks_.emplace_back().fill(-1);
    last_key_ = key;
    last_block_ = &blocks_[it->second];
  }
  constexpr int64_t m = kBlockSide - 1;
  return (*last_block_)[((cx & m) << (2 * kBlockBits)) | ((cy & m) << kBlockBits) | (cz & m)];
}

void VoxelMap::add(const Eigen::Vector3d& p, const Eigen::Vector3f& local, int keyframe, float intensity, bool keep) {
  const Eigen::Vector3d c = (p * inverse_voxel_).array().floor();
  const int64_t cx = static_cast<int64_t>(c.x()), cy = static_cast<int64_t>(c.y()), cz = static_cast<int64_t>(c.z());
  // A scan's consecutive points often share a voxel (near the sensor a 0.2 m cell holds several
  // points of a ring): only the first of a run looks the cell up.
  if (!keep && cx == last_cell_[0] && cy == last_cell_[1] && cz == last_cell_[2]) return;
  last_cell_ = {cx, cy, cz};
  int32_t& s = slot(cx, cy, cz);
  if (s >= 0 && !keep) return;  // the voxel's first point stands for it
  if (s < 0) s = static_cast<int32_t>(voxels_.size());
  voxels_.push_back(Voxel{local, keyframe, intensity});
}

size_t VoxelMap::insert(int keyframe, const Pose& T, const PointCloud& points) {
  if (keyframe < 0) throw std::invalid_argument("VoxelMap::insert: negative keyframe id");
  if (static_cast<size_t>(keyframe) >= poses_.size()) poses_.resize(keyframe + 1, Pose::Identity());
  poses_[keyframe] = T;
  last_cell_ = {kNoCell, kNoCell, kNoCell};
  const size_t before = voxels_.size();
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const Eigen::Vector3f local = points.col(i).head<3>();
    add(T * local.cast<double>(), local, keyframe, points(3, i));
  }
  return voxels_.size() - before;
}

void VoxelMap::repose(const std::vector<Pose>& T_map_keyframe) {
  std::vector<Voxel> old;
  old.swap(voxels_);
  blocks_.clear();
  block_index_.clear();
  last_key_ = ~uint64_t{0};
  last_block_ = nullptr;
  last_cell_ = {kNoCell, kNoCell, kNoCell};
  for (size_t k = 0; k < poses_.size() && k < T_map_keyframe.size(); ++k) poses_[k] = T_map_keyframe[k];
  voxels_.reserve(old.size());
  for (const Voxel& v : old) add(poses_.at(v.keyframe) * v.local.cast<double>(), v.local, v.keyframe, v.intensity, true);
}

PointCloud VoxelMap::cloud() const {
  PointCloud out(4, static_cast<Eigen::Index>(voxels_.size()));
  for (size_t i = 0; i < voxels_.size(); ++i) {
    const Voxel& v = voxels_[i];
    out.col(static_cast<Eigen::Index>(i)).head<3>() = (poses_[v.keyframe] * v.local.cast<double>()).cast<float>();
    out(3, static_cast<Eigen::Index>(i)) = v.intensity;
  }
  return out;
}

size_t VoxelMap::memoryBytes() const {
  return voxels_.capacity() * sizeof(Voxel) + blocks_.size() * sizeof(Block) +
         block_index_.size() * (sizeof(uint64_t) + sizeof(int32_t) + 2 * sizeof(void*));
}

}  // namespace dlslot::mapper
