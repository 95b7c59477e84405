// The local map of scan-to-map refinement (A-LOAM laserMapping): edge and plane feature points
// in the world frame on voxel grids (one running-mean point per voxel), bounded to a radius
// around the vehicle.
//
// The map is updated in place, never rebuilt: voxels are grouped in cubic blocks (m x m x m
// voxels, m the smallest with a block edge >= the neighbour search radius) held in one
// contiguous array and found through a hash of the block coordinates (as KISS-ICP's
// VoxelHashMap and iVox). A scan adds its points to their voxels' means, cropping drops whole
// blocks, and a nearest-neighbour query within the search radius visits only the 2-3 blocks per
// axis that the radius overlaps. The kd-tree it replaces was rebuilt over the whole map after
// every scan (crop + re-index: 6.4 % of the odometry's instructions on the real slice) and its
// searches took another 14 %.
#pragma once

#include <cstdint>
#include <vector>

#include "block_index.hpp"
#include "feature_extraction.hpp"

namespace dlslot::odometry {

// The nearest map points of a query, nearest first (reused between queries: no allocation).
struct Neighbours {
  std::vector<float> d2;
  std::vector<Eigen::Vector3f> points;
  int size() const { return static_cast<int>(d2.size()); }
};

class VoxelLayer {
 public:
  // voxel_m: the grid; search_radius_m: the largest distance nearest() is asked for.
  VoxelLayer(double voxel_m, double search_radius_m);
  // Adds points (moved to the world frame by T_world_lidar): each lands in its voxel's running mean.
  void insert(const FeatureCloud& points, const Eigen::Isometry3f& T_world_lidar);
  // Drops voxels whose mean is farther than radius (horizontally) from `center`.
  void crop(const Eigen::Vector3d& center, double radius);
  void clear();
  size_t size() const { return num_points_; }
  // The k voxel means nearest to q closer than the search radius (fewer when there are not k).
  void nearest(const Eigen::Vector3f& q, int k, Neighbours& out) const;
  // Every voxel mean (for tests and inspection).
  std::vector<Eigen::Vector3f> points() const;

 private:
  struct Block {
    int64_t key;
    int64_t bx, by, bz;  // block coordinates
    int n = 0;           // occupied voxels: entries [0, n) of its slots in the flat arrays
  };
  int64_t blockKey(int64_t bx, int64_t by, int64_t bz) const;
  void removeBlock(size_t b);
  void removePoint(size_t b, int i);

  double voxel_, block_;
  int m_;            // voxels per block edge
  int capacity_;     // m^3: voxels per block
  float radius2_;
  std::vector<Block> blocks_;
  BlockIndex index_;
  // Per block b, entries [b * capacity_, b * capacity_ + blocks_[b].n): the voxel (its index
  // within the block), its mean and its count.
  std::vector<Eigen::Vector3f> means_;
  std::vector<int> counts_;
  std::vector<int> slots_;
  size_t num_points_ = 0;
};

class LocalMap {
 public:
  explicit LocalMap(const ScanToMapConfig& cfg)
      : edges_(cfg.edge_voxel_m, cfg.max_neighbor_distance_m),
        planes_(cfg.plane_voxel_m, cfg.max_neighbor_distance_m),
        radius_(cfg.map_radius_m) {}
  // Adds one scan's features (lidar frame) seen from T_world_lidar, then re-centres the map on it.
  void insert(const FeatureCloud& edges, const FeatureCloud& planes, const Pose& T_world_lidar);
  void clear();
  bool empty() const { return edges_.size() == 0 && planes_.size() == 0; }
  const VoxelLayer& edges() const { return edges_; }
  const VoxelLayer& planes() const { return planes_; }

 private:
  VoxelLayer edges_, planes_;
  double radius_;
};

// Voxel-grid downsampling (centroid per voxel), as A-LOAM thins a scan before mapping.
FeatureCloud downsample(const FeatureCloud& cloud, double voxel_m);

}  // namespace dlslot::odometry
