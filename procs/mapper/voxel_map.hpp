// The static map: one point per occupied voxel, each anchored to the keyframe that first saw it
// (the point is kept in that keyframe's frame). When loop closure moves the keyframes, every
// voxel moves with its keyframe (repose), so the map follows the corrected trajectory without
// keeping every keyframe's scan: memory is bounded by the occupied voxels (KISS-ICP's voxel hash
// map, with an anchor per voxel).
//
// Storage is block-hashed (voxblox / OpenVDB style): the hash holds blocks of 8 x 8 x 8 voxels,
// each a dense table of indices into one flat array of voxels. A scan's consecutive points fall
// in the same block, so most points cost an array lookup instead of a hash lookup and a heap node
// per voxel (a std::unordered_map of voxels was 40 % of the mapper's CPU time and ~60 bytes a
// voxel; here a voxel is 20 bytes plus its share of its block's table).
#pragma once

#include <array>
#include <climits>
#include <cstdint>
#include <deque>
#include <unordered_map>
#include <vector>

#include "dlslot/types.hpp"

namespace dlslot::mapper {

class VoxelMap {
 public:
  explicit VoxelMap(double voxel_m) : voxel_(voxel_m), inverse_voxel_(1.0 / voxel_m) {}

  // points: the keyframe's points (x y z intensity columns) in its own frame; T_map_keyframe its pose.
  // Returns the number of voxels the keyframe added (how much of what it saw is new).
  size_t insert(int keyframe, const Pose& T_map_keyframe, const PointCloud& points);
  // Re-places every voxel with its keyframe's new pose (poses indexed by keyframe id). Voxels
  // that now share a cell are all kept (the cell indexes the first; a later point there adds
  // nothing): a loop correction moves neighbouring keyframes by sub-voxel amounts, and merging on
  // the moved grid would drop ~30 % of the points (urban-loop) only because the grid no longer
  // lines up with them, not because they duplicate anything. So the map holds one point per
  // voxel of the grid its points were counted on (each keyframe's pose at insertion).
  void repose(const std::vector<Pose>& T_map_keyframe);
  // One point per voxel, map frame: x y z and intensity of the first point that fell in it (a
  // voxel's first point stands for it: a later point only costs a look-up, no write to the voxel).
  PointCloud cloud() const;
  size_t size() const { return voxels_.size(); }
  double voxelSize() const { return voxel_; }
  // Bytes held by the voxels and their blocks (what grows with the map).
  size_t memoryBytes() const;

 private:
  struct Voxel {
    Eigen::Vector3f local;  // the first point, in its keyframe's frame
    int32_t keyframe = 0;
    float intensity = 0;
  };
  static constexpr int kBlockBits = 3, kBlockSide = 1 << kBlockBits, kBlockCells = kBlockSide * kBlockSide * kBlockSide;
  using Block = std::array<int32_t, kBlockCells>;  // index into voxels_, or -1

  // The voxel slot of cell (cx, cy, cz) of the grid (corner at the origin, as voxelKey).
  int32_t& slot(int64_t cx, int64_t cy, int64_t cz);
  // Adds one point (map frame `p`, its keyframe-frame `local`): a new voxel when its cell is empty
  // (always, with `keep`: a voxel re-placed by repose).
  void add(const Eigen::Vector3d& p, const Eigen::Vector3f& local, int keyframe, float intensity, bool keep = false);
  static constexpr int64_t kNoCell = INT64_MIN;

  double voxel_, inverse_voxel_;
  std::vector<Voxel> voxels_;
  std::deque<Block> blocks_;                         // stable addresses
  std::unordered_map<uint64_t, int32_t> block_index_;  // packed block coordinates -> blocks_ index
  uint64_t last_key_ = ~uint64_t{0};                 // the block of the previous point
  Block* last_block_ = nullptr;
  std::array<int64_t, 3> last_cell_{kNoCell, kNoCell, kNoCell};  // the cell of the previous point
  std::vector<Pose> poses_;  // the pose each keyframe was inserted with (or last reposed to)
};

}  // namespace dlslot::mapper
