// The local map of scan-to-map refinement (A-LOAM laserMapping): edge and plane feature points
// in the world frame on voxel grids (one running-mean point per voxel), bounded to a radius
// around the vehicle, each with a kd-tree for the nearest-neighbour searches.
#pragma once

#include <pcl/kdtree/kdtree_flann.h>

#include <cstdint>
#include <unordered_map>

#include "feature_extraction.hpp"

namespace dlslot::odometry {

class VoxelLayer {
 public:
  explicit VoxelLayer(double voxel_m) : voxel_(voxel_m) {}
  // Adds world-frame points: each lands in its voxel's running mean.
  void insert(const FeatureCloud& points_world);
  // Drops voxels farther than radius (horizontally) from `center`, and rebuilds the kd-tree.
  void crop(const Eigen::Vector3d& center, double radius);
  void clear();
  const FeatureCloud& cloud() const { return *cloud_; }
  const pcl::KdTreeFLANN<pcl::PointXYZI>& tree() const { return tree_; }
  size_t size() const { return cloud_->size(); }

 private:
  struct Cell {
    Eigen::Vector3f mean;
    int count = 0;
  };
  int64_t key(const Eigen::Vector3f& p) const;
  double voxel_;
  std::unordered_map<int64_t, Cell> cells_;
  FeatureCloud::Ptr cloud_{new FeatureCloud};
  pcl::KdTreeFLANN<pcl::PointXYZI> tree_;
};

class LocalMap {
 public:
  LocalMap(double edge_voxel_m, double plane_voxel_m, double radius_m)
      : edges_(edge_voxel_m), planes_(plane_voxel_m), radius_(radius_m) {}
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

// PCL voxel-grid downsampling (centroid per voxel), as A-LOAM thins a scan before mapping.
FeatureCloud downsample(const FeatureCloud& cloud, double voxel_m);
// The cloud moved by T (intensity kept).
FeatureCloud transformed(const FeatureCloud& cloud, const Pose& T);

}  // namespace dlslot::odometry
