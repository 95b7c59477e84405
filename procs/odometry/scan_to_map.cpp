#include "scan_to_map.hpp"

#include <Eigen/Eigenvalues>

namespace dlslot::odometry {

namespace {

// The k nearest map points of q as columns of `out`, or false when there are not k within the
// search radius (cfg.max_neighbor_distance_m, the map's).
bool neighbours(const VoxelLayer& layer, const Eigen::Vector3f& q, int k, Neighbours& nb, Eigen::Matrix3Xd& out) {
  layer.nearest(q, k, nb);
  if (nb.size() < k) return false;
  out.resize(3, k);
  for (int j = 0; j < k; ++j) out.col(j) = nb.points[j].cast<double>();
  return true;
}

}  // namespace

Matches matchScanToMap(const FeatureCloud& edges, const FeatureCloud& planes, const LocalMap& map,
                       const Pose& T_world_lidar, const ScanToMapConfig& cfg) {
  Matches m;
  m.edges.reserve(edges.size());
  m.planes.reserve(planes.size());
  const Eigen::Isometry3f T = T_world_lidar.cast<float>();
  Eigen::Matrix3Xd nb;
  Neighbours found;

  // An edge point matches the line through its neighbours when they are spread along one
  // direction (largest covariance eigenvalue dominates the second).
  for (const auto& pt : edges) {
    const Eigen::Vector3f p = pt.getVector3fMap();
    if (!neighbours(map.edges(), T * p, cfg.neighbors, found, nb)) continue;
    const Eigen::Vector3d mean = nb.rowwise().mean();
    const Eigen::Matrix3Xd centred = nb.colwise() - mean;
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
    eig.computeDirect(centred * centred.transpose());
    if (eig.eigenvalues()[2] <= cfg.edge_eigen_ratio * eig.eigenvalues()[1]) continue;
    m.edges.push_back({p.cast<double>(), mean, eig.eigenvectors().col(2)});
  }

  // A plane point matches the plane fitted to its neighbours when every neighbour lies on it.
  for (const auto& pt : planes) {
    const Eigen::Vector3f p = pt.getVector3fMap();
    if (!neighbours(map.planes(), T * p, cfg.neighbors, found, nb)) continue;
    const Eigen::Vector3d mean = nb.rowwise().mean();
    const Eigen::Matrix3Xd centred = nb.colwise() - mean;
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
    eig.computeDirect(centred * centred.transpose());
    const Eigen::Vector3d n = eig.eigenvectors().col(0);
    if ((n.transpose() * centred).cwiseAbs().maxCoeff() > cfg.plane_max_deviation_m) continue;
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
