#include "scan_to_scan.hpp"

#include <cmath>
#include <limits>
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

double outlierShift(const Matches& matches, const Pose& T_ref_cur, const Eigen::Vector3d& v, double huber_delta,
                    double spacing, double max_abs_shift, int min_votes) {
  const int bins = 2 * static_cast<int>(std::ceil(max_abs_shift / spacing)) + 1;
  std::vector<int> count(bins, 0);
  std::vector<double> sum(bins, 0.0);
  auto vote = [&](double s) {
    if (!(std::abs(s) <= max_abs_shift)) return;
    const int b = static_cast<int>(std::lround(s / spacing)) + bins / 2;
    if (b < 0 || b >= bins) return;
    ++count[b];
    sum[b] += s;
  };
  // A correspondence is informative along v when v moves it at least half as much as along its
  // own residual direction (cos 60 deg).
  for (const EdgeMatch& m : matches.edges) {
    const Eigen::Vector3d q = T_ref_cur * m.p - m.a;
    const Eigen::Vector3d e = q - m.u * m.u.dot(q);  // perpendicular residual
    const Eigen::Vector3d w = v - m.u * m.u.dot(v);   // what a unit shift along v does to it
    if (w.norm() < 0.5) continue;
    if (e.norm() <= huber_delta) continue;
    const double s = -e.dot(w) / w.squaredNorm();
    if ((e + s * w).norm() <= huber_delta) vote(s);   // the shift explains the residual
  }
  for (const PlaneMatch& m : matches.planes) {
    const double r = m.n.dot(T_ref_cur * m.p) + m.d;
    if (std::abs(m.n.dot(v)) < 0.5) continue;
    if (std::abs(r) <= huber_delta) continue;
    vote(-r / m.n.dot(v));
  }
  int best = -1;
  for (int b = 0; b < bins; ++b)
    // The bins next to no shift hold the residuals' own tails, and a motion that close is
    // within the registration's reach anyway (it converges from there).
    if (std::abs(b - bins / 2) > 1 && (best < 0 || count[b] > count[best])) best = b;
  if (best < 0 || count[best] < min_votes) return std::numeric_limits<double>::quiet_NaN();
  return sum[best] / count[best];
}

std::vector<double> forwardHypotheses(const ScanToScanConfig& cfg) {
  std::vector<double> out;
  const int steps = static_cast<int>(std::floor(cfg.max_forward_m / cfg.hypothesis_spacing_m + 1e-9));
  for (int k = 0; k <= steps; ++k) out.push_back(k * cfg.hypothesis_spacing_m);
  return out;
}

Registration registerMotionHypotheses(const ScanFeatures& current, ScanReference& previous, const Pose& guess,
                                      const std::vector<double>& forward, const ScanToScanConfig& cfg,
                                      int* hypotheses) {
  Registration best;
  double match_ms = 0.0, solve_ms = 0.0;
  auto tryFrom = [&](const Pose& start) {
    const Registration r = registerScanToScan(current, previous, start, cfg);
    match_ms += r.match_ms;
    solve_ms += r.solve_ms;
    if (r.solution.ok && (!best.solution.ok || r.solution.num_inliers > best.solution.num_inliers)) best = r;
  };
  tryFrom(guess);
  int n = 1;
  for (double d : forward) {
    Pose start = guess;
    start.translation() = Eigen::Vector3d(d, 0.0, 0.0);
    // The guess itself is tried already; a start within half a spacing of it adds nothing.
    if ((start.translation() - guess.translation()).norm() < 0.5 * cfg.hypothesis_spacing_m) continue;
    tryFrom(start);
    ++n;
  }
  if (hypotheses) *hypotheses = n;
  best.match_ms = match_ms;
  best.solve_ms = solve_ms;
  return best;
}

}  // namespace dlslot::odometry
