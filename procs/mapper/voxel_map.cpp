#include "mapper/voxel_map.hpp"

#include <stdexcept>

#include "dlslot/voxel_key.hpp"

namespace dlslot::mapper {

void VoxelMap::insert(int keyframe, const Pose& T, const PointCloud& points) {
  if (keyframe < 0) throw std::invalid_argument("VoxelMap::insert: negative keyframe id");
  if (static_cast<size_t>(keyframe) >= poses_.size()) poses_.resize(keyframe + 1, Pose::Identity());
  poses_[keyframe] = T;
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const Eigen::Vector3f local = points.col(i).head<3>();
    const uint64_t key = voxelKey(T * local.cast<double>(), voxel_);
    auto [it, inserted] = voxels_.try_emplace(key);
    if (inserted) {
      it->second.local = local;
      it->second.keyframe = keyframe;
    }
    it->second.intensity_sum += points(3, i);
    ++it->second.count;
  }
}

void VoxelMap::repose(const std::vector<Pose>& T_map_keyframe) {
  std::unordered_map<uint64_t, Voxel> moved;
  moved.reserve(voxels_.size());
  for (const auto& [key, v] : voxels_) {
    const Pose& T = static_cast<size_t>(v.keyframe) < T_map_keyframe.size() ? T_map_keyframe[v.keyframe]
                                                                             : poses_.at(v.keyframe);
    auto [it, inserted] = moved.try_emplace(voxelKey(T * v.local.cast<double>(), voxel_), v);
    if (!inserted) {
      it->second.intensity_sum += v.intensity_sum;
      it->second.count += v.count;
    }
  }
  voxels_ = std::move(moved);
  for (size_t k = 0; k < poses_.size() && k < T_map_keyframe.size(); ++k) poses_[k] = T_map_keyframe[k];
}

PointCloud VoxelMap::cloud() const {
  PointCloud out(4, static_cast<Eigen::Index>(voxels_.size()));
  Eigen::Index i = 0;
  for (const auto& [key, v] : voxels_) {
    out.col(i).head<3>() = (poses_[v.keyframe] * v.local.cast<double>()).cast<float>();
    out(3, i) = v.intensity_sum / static_cast<float>(v.count);
    ++i;
  }
  return out;
}

}  // namespace dlslot::mapper
