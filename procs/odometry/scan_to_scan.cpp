#include "scan_to_scan.hpp"

#include <cmath>

namespace dlslot::odometry {

void ScanReference::reset(const ScanFeatures& f) {
  *edges_ = f.less_sharp;
  *planes_ = f.less_flat;
  if (!edges_->empty()) edge_tree_.setInputCloud(edges_);
  if (!planes_->empty()) plane_tree_.setInputCloud(planes_);
}

namespace {

Eigen::Vector3d vec(const pcl::PointXYZI& p) { return {p.x, p.y, p.z}; }
int beamOf(const pcl::PointXYZI& p) { return static_cast<int>(p.intensity); }

// Nearest reference point to q, or -1 when farther than max_dist2.
int nearest(const pcl::KdTreeFLANN<pcl::PointXYZI>& tree, const pcl::PointXYZI& q, double max_dist2) {
  std::vector<int> idx(1);
  std::vector<float> d2(1);
  if (tree.nearestKSearch(q, 1, idx, d2) < 1 || d2[0] >= max_dist2) return -1;
  return idx[0];
}

// Closest point to q among the points of `cloud` whose beam satisfies `accept`, walking outwards
// from index `from` through the beam-ordered cloud until beams are more than `nearby` away.
template <class Accept>
int closestInNearbyBeams(const FeatureCloud& cloud, int from, const pcl::PointXYZI& q, int nearby,
                         double max_dist2, Accept accept) {
  const int beam0 = beamOf(cloud[from]);
  int best = -1;
  double best_d2 = max_dist2;
  for (int dir : {1, -1}) {
    for (int j = from + dir; j >= 0 && j < static_cast<int>(cloud.size()); j += dir) {
      const int beam = beamOf(cloud[j]);
      if (std::abs(beam - beam0) > nearby) break;
      if (!accept(beam, beam0)) continue;
      const double d2 = (vec(cloud[j]) - vec(q)).squaredNorm();
      if (d2 < best_d2) {
        best_d2 = d2;
        best = j;
      }
    }
  }
  return best;
}

}  // namespace

Matches matchScanToScan(const ScanFeatures& current, const ScanReference& previous, const Pose& T_prev_cur,
                        const ScanToScanConfig& cfg) {
  Matches m;
  const double max_d2 = cfg.max_match_distance_m * cfg.max_match_distance_m;
  const Pose T = T_prev_cur;
  auto moved = [&](const pcl::PointXYZI& p) {
    pcl::PointXYZI q = p;
    q.getVector3fMap() = (T * vec(p)).cast<float>();
    return q;
  };

  // Edge point -> the line through its nearest previous edge point and the nearest edge point
  // of a neighbouring beam.
  if (!previous.edges().empty()) {
    const FeatureCloud& ref = previous.edges();
    for (const auto& p : current.sharp) {
      const pcl::PointXYZI q = moved(p);
      const int a = nearest(previous.edgeTree(), q, max_d2);
      if (a < 0) continue;
      const int b = closestInNearbyBeams(ref, a, q, cfg.nearby_beams, max_d2,
                                         [](int beam, int beam0) { return beam != beam0; });
      if (b < 0) continue;
      const Eigen::Vector3d pa = vec(ref[a]), pb = vec(ref[b]);
      if ((pb - pa).norm() < 1e-3) continue;
      m.edges.push_back({vec(p), pa, (pb - pa).normalized()});
    }
  }

  // Plane point -> the plane through its nearest previous plane point, the nearest one of the
  // same beam and the nearest one of another beam (three points not on one ring).
  if (!previous.planes().empty()) {
    const FeatureCloud& ref = previous.planes();
    for (const auto& p : current.flat) {
      const pcl::PointXYZI q = moved(p);
      const int a = nearest(previous.planeTree(), q, max_d2);
      if (a < 0) continue;
      const int b = closestInNearbyBeams(ref, a, q, cfg.nearby_beams, max_d2,
                                         [](int beam, int beam0) { return beam == beam0; });
      const int c = closestInNearbyBeams(ref, a, q, cfg.nearby_beams, max_d2,
                                         [](int beam, int beam0) { return beam != beam0; });
      if (b < 0 || c < 0) continue;
      const Eigen::Vector3d pa = vec(ref[a]);
      const Eigen::Vector3d normal = (vec(ref[b]) - pa).cross(vec(ref[c]) - pa);
      if (normal.norm() < 1e-6) continue;  // collinear
      const Eigen::Vector3d n = normal.normalized();
      m.planes.push_back({vec(p), n, -n.dot(pa)});
    }
  }
  return m;
}

Registration registerScanToScan(const ScanFeatures& current, const ScanReference& previous,
                                    const Pose& guess, const ScanToScanConfig& cfg) {
  return registerIteratively([&](const Pose& T) { return matchScanToScan(current, previous, T, cfg); }, guess, cfg.solver,
                             cfg.min_correspondences);
}

}  // namespace dlslot::odometry
