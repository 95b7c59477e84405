#include "scan_to_scan.hpp"

#include <cmath>
#include <utility>

namespace dlslot::odometry {

void ScanReference::reset(ScanFeatures f) {
  edges_ = std::move(f.less_sharp);
  planes_ = std::move(f.less_flat);
  indexed_ = false;
}

void ScanReference::index() {
  if (indexed_) return;
  edge_grid_.build(edges_);
  plane_grid_.build(planes_);
  indexed_ = true;
}

namespace {

Eigen::Vector3d vec(const pcl::PointXYZI& p) { return {p.x, p.y, p.z}; }
int beamOf(const pcl::PointXYZI& p) { return static_cast<int>(p.intensity); }

// The reference points nearest to q (closest first) within max_dist2, at most k.
struct Candidates {
  std::vector<int> idx;
  std::vector<float> d2;
};
void nearestCandidates(const PointGrid& grid, const Eigen::Vector3f& q, int k, double max_dist2, Candidates& c) {
  grid.nearest(q, k, static_cast<float>(max_dist2), c.idx, c.d2);
}

// The closest candidate after the first whose beam satisfies `accept(beam, beam of the first)`
// and lies within `nearby` beams of it (A-LOAM's rule for the other points of a line or plane).
template <class Accept>
int closestOf(const Candidates& c, const FeatureCloud& cloud, int nearby, Accept accept) {
  const int beam0 = beamOf(cloud[c.idx[0]]);
  for (size_t k = 1; k < c.idx.size(); ++k) {
    const int beam = beamOf(cloud[c.idx[k]]);
    if (std::abs(beam - beam0) <= nearby && accept(beam, beam0)) return c.idx[k];
  }
  return -1;
}

}  // namespace

Matches matchScanToScan(const ScanFeatures& current, const ScanReference& previous, const Pose& T_prev_cur,
                        const ScanToScanConfig& cfg) {
  Matches m;
  Candidates c;
  const double max_d2 = cfg.max_match_distance_m * cfg.max_match_distance_m;
  auto moved = [&](const pcl::PointXYZI& p) -> Eigen::Vector3f { return (T_prev_cur * vec(p)).cast<float>(); };

  // Edge point -> the line through its nearest previous edge point and the nearest edge point
  // of a neighbouring beam.
  if (!previous.edges().empty()) {
    const FeatureCloud& ref = previous.edges();
    for (const auto& p : current.sharp) {
      nearestCandidates(previous.edgeGrid(), moved(p), cfg.candidates, max_d2, c);
      if (c.idx.empty()) continue;
      const int a = c.idx[0];
      const int b = closestOf(c, ref, cfg.nearby_beams, [](int beam, int beam0) { return beam != beam0; });
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
      nearestCandidates(previous.planeGrid(), moved(p), cfg.candidates, max_d2, c);
      if (c.idx.empty()) continue;
      const int a = c.idx[0];
      const int b = closestOf(c, ref, cfg.nearby_beams, [](int beam, int beam0) { return beam == beam0; });
      const int d = closestOf(c, ref, cfg.nearby_beams, [](int beam, int beam0) { return beam != beam0; });
      if (b < 0 || d < 0) continue;
      const Eigen::Vector3d pa = vec(ref[a]);
      const Eigen::Vector3d normal = (vec(ref[b]) - pa).cross(vec(ref[d]) - pa);
      if (normal.norm() < 1e-6) continue;  // collinear
      const Eigen::Vector3d n = normal.normalized();
      m.planes.push_back({vec(p), n, -n.dot(pa)});
    }
  }
  return m;
}

Registration registerScanToScan(const ScanFeatures& current, ScanReference& previous, const Pose& guess,
                                const ScanToScanConfig& cfg) {
  previous.index();
  return registerIteratively([&](const Pose& T) { return matchScanToScan(current, previous, T, cfg); }, guess, cfg.solver,
                             cfg.min_correspondences);
}

Registration registerFirstMotion(const ScanFeatures& current, ScanReference& previous, const ScanToScanConfig& cfg) {
  Registration best;
  for (double forward : cfg.first_motion_guesses_m) {
    Pose guess = Pose::Identity();
    guess.translation().x() = forward;
    const Registration r = registerScanToScan(current, previous, guess, cfg);
    if (r.solution.ok && (!best.solution.ok || r.solution.num_inliers > best.solution.num_inliers)) best = r;
  }
  return best;
}

}  // namespace dlslot::odometry
