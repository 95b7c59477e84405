// The static map: one point per occupied voxel, each anchored to the keyframe that first saw it
// (the point is kept in that keyframe's frame). When loop closure moves the keyframes, every
// voxel moves with its keyframe (repose), so the map follows the corrected trajectory without
// keeping every keyframe's scan: memory is bounded by the occupied voxels (KISS-ICP's voxel hash
// map, with an anchor per voxel).
#pragma once

#include <cstdint>
#include <unordered_map>
#include <vector>

#include "dlslot/types.hpp"

namespace dlslot::mapper {

class VoxelMap {
 public:
  explicit VoxelMap(double voxel_m) : voxel_(voxel_m) {}

  // points: the keyframe's points (x y z intensity columns) in its own frame; T_map_keyframe its pose.
  void insert(int keyframe, const Pose& T_map_keyframe, const PointCloud& points);
  // Re-places every voxel with its keyframe's new pose (poses indexed by keyframe id); voxels
  // that now share a cell are merged.
  void repose(const std::vector<Pose>& T_map_keyframe);
  // One point per voxel, map frame: x y z and the mean intensity of the points it holds.
  PointCloud cloud() const;
  size_t size() const { return voxels_.size(); }
  double voxelSize() const { return voxel_; }

 private:
  struct Voxel {
    Eigen::Vector3f local;  // the first point, in its keyframe's frame
    int keyframe = 0;
    float intensity_sum = 0;
    int count = 0;
  };
  double voxel_;
  std::unordered_map<uint64_t, Voxel> voxels_;
  std::vector<Pose> poses_;  // the pose each keyframe was inserted with (or last reposed to)
};

}  // namespace dlslot::mapper
