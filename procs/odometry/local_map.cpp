#include "local_map.hpp"

#include <pcl/filters/voxel_grid.h>

#include <cmath>

namespace dlslot::odometry {

int64_t VoxelLayer::key(const Eigen::Vector3f& p) const {
  // 21 bits per axis: +-1e6 voxels, far beyond any local map.
  auto idx = [this](float v) { return static_cast<int64_t>(std::floor(v / voxel_)) + (int64_t{1} << 20); };
  return (idx(p.x()) << 42) | (idx(p.y()) << 21) | idx(p.z());
}

void VoxelLayer::insert(const FeatureCloud& points) {
  for (const auto& pt : points) {
    const Eigen::Vector3f p = pt.getVector3fMap();
    Cell& c = cells_[key(p)];
    // A running mean averages the range noise of repeated observations of the same surface.
    c.mean = c.count == 0 ? p : Eigen::Vector3f(c.mean + (p - c.mean) / static_cast<float>(c.count + 1));
    ++c.count;
  }
}

void VoxelLayer::crop(const Eigen::Vector3d& center, double radius) {
  const float r2 = static_cast<float>(radius * radius);
  const Eigen::Vector2f c = center.head<2>().cast<float>();
  cloud_.reset(new FeatureCloud);
  cloud_->reserve(cells_.size());
  for (auto it = cells_.begin(); it != cells_.end();) {
    if ((it->second.mean.head<2>() - c).squaredNorm() > r2) {
      it = cells_.erase(it);
      continue;
    }
    pcl::PointXYZI q;
    q.getVector3fMap() = it->second.mean;
    q.intensity = 0.0f;
    cloud_->push_back(q);
    ++it;
  }
  if (!cloud_->empty()) tree_.setInputCloud(cloud_);
}

void VoxelLayer::clear() {
  cells_.clear();
  cloud_.reset(new FeatureCloud);
}

void LocalMap::insert(const FeatureCloud& edges, const FeatureCloud& planes, const Pose& T_world_lidar) {
  edges_.insert(transformed(edges, T_world_lidar));
  planes_.insert(transformed(planes, T_world_lidar));
  edges_.crop(T_world_lidar.translation(), radius_);
  planes_.crop(T_world_lidar.translation(), radius_);
}

void LocalMap::clear() {
  edges_.clear();
  planes_.clear();
}

FeatureCloud downsample(const FeatureCloud& cloud, double voxel_m) {
  FeatureCloud out;
  if (cloud.empty()) return out;
  pcl::VoxelGrid<pcl::PointXYZI> grid;
  const float v = static_cast<float>(voxel_m);
  grid.setLeafSize(v, v, v);
  grid.setInputCloud(FeatureCloud::ConstPtr(&cloud, [](const FeatureCloud*) {}));
  grid.filter(out);
  return out;
}

FeatureCloud transformed(const FeatureCloud& cloud, const Pose& T) {
  FeatureCloud out = cloud;
  const Eigen::Isometry3f Tf = T.cast<float>();
  for (auto& p : out.points) p.getVector3fMap() = Tf * p.getVector3fMap();
  return out;
}

}  // namespace dlslot::odometry
