#include "scan_to_map.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace dlslot::odometry {

namespace {

// The k nearest map points of q (found.points), their mean and scatter matrix, or false when
// there are not k within the search radius (cfg.max_neighbor_distance_m, the map's). In double
// as A-LOAM fits them; no allocation per query (this runs ~10^4 times a search).
bool fitNeighbours(const VoxelLayer& layer, const Eigen::Vector3f& q, int k, Neighbours& found, Eigen::Vector3d& mean,
                   Eigen::Matrix3d& scatter) {
  layer.nearest(q, k, found);
  if (found.size() < k) return false;
  mean.setZero();
  for (int j = 0; j < k; ++j) mean += found.points[j].cast<double>();
  mean /= k;
  scatter.setZero();
  for (int j = 0; j < k; ++j) {
    const Eigen::Vector3d d = found.points[j].cast<double>() - mean;
    scatter.noalias() += d * d.transpose();
  }
  return true;
}

}  // namespace

Matches matchScanToMap(const FeatureCloud& edges, const FeatureCloud& planes, const LocalMap& map,
                       const Pose& T_world_lidar, const ScanToMapConfig& cfg) {
  Matches m;
  m.edges.reserve(edges.size());
  m.planes.reserve(planes.size());
  const Eigen::Isometry3f T = T_world_lidar.cast<float>();
  Neighbours found;
  Eigen::Vector3d mean;
  Eigen::Matrix3d scatter;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  const double min_vertical = std::cos(cfg.edge_max_tilt_deg * M_PI / 180.0) - 1e-12;

  // An edge point matches the line through its neighbours when they are spread along one
  // direction (largest covariance eigenvalue dominates the second).
  for (const auto& pt : edges) {
    const Eigen::Vector3f p = pt.getVector3fMap();
    if (!fitNeighbours(map.edges(), T * p, cfg.neighbors, found, mean, scatter)) continue;
    eig.computeDirect(scatter);
    if (eig.eigenvalues()[2] <= cfg.edge_eigen_ratio * eig.eigenvalues()[1]) continue;
    if (std::abs(eig.eigenvectors().col(2).z()) < min_vertical) continue;
    m.edges.push_back({p.cast<double>(), mean, eig.eigenvectors().col(2)});
  }

  // A plane point matches the plane fitted to its neighbours when every neighbour lies on it.
  for (const auto& pt : planes) {
    const Eigen::Vector3f p = pt.getVector3fMap();
    if (!fitNeighbours(map.planes(), T * p, cfg.neighbors, found, mean, scatter)) continue;
    eig.computeDirect(scatter);
    const Eigen::Vector3d n = eig.eigenvectors().col(0);
    double deviation = 0.0;
    for (int j = 0; j < cfg.neighbors; ++j)
      deviation = std::max(deviation, std::abs(n.dot(found.points[j].cast<double>() - mean)));
    if (deviation > cfg.plane_max_deviation_m) continue;
    m.planes.push_back({p.cast<double>(), n, -n.dot(mean)});
  }
  return m;
}

Registration registerScanToMap(const FeatureCloud& edges, const FeatureCloud& planes, const LocalMap& map,
                                  const Pose& guess, const ScanToMapConfig& cfg) {
  return registerIteratively([&](const Pose& T) { return matchScanToMap(edges, planes, map, T, cfg); }, guess, cfg.solver,
                             cfg.min_correspondences);
}

}  // namespace dlslot::odometry
