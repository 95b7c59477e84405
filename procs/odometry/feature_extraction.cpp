#include "feature_extraction.hpp"

#include <algorithm>
#include <functional>
#include <memory>
#include <string>
#include <cmath>
#include <numeric>
#include <utility>

#include "beam_index.hpp"
#include "curvature.hpp"

namespace dlslot::odometry {

namespace {

enum Label : int8_t { kNone = 0, kLessSharp = 1, kSharp = 2, kFlat = -1 };

// The points of one scan, regrouped ring by ring (firing order kept within a ring).
struct Rings {
  Eigen::Matrix3Xf points;
  std::vector<int> start;  // ring b is columns [start[b], start[b+1])
};

// The beam model of `cfg`, built once per thread and configuration (its tables took 0.6 % of the
// odometry's instructions when built for every scan).
const BeamModel& beamModelFor(const FeatureConfig& cfg) {
  struct Cached {
    std::string beam_model;
    int num_beams;
    double min_deg, max_deg;
    BeamModel model;
  };
  thread_local std::unique_ptr<Cached> cache;
  if (!cache || cache->beam_model != cfg.beam_model || cache->num_beams != cfg.num_beams ||
      cache->min_deg != cfg.min_vertical_deg || cache->max_deg != cfg.max_vertical_deg)
    cache.reset(new Cached{cfg.beam_model, cfg.num_beams, cfg.min_vertical_deg, cfg.max_vertical_deg, BeamModel(cfg)});
  return cache->model;
}

Rings groupByBeam(const PointCloud& scan, const FeatureConfig& cfg, const std::vector<bool>* removed) {
  const BeamModel& model = beamModelFor(cfg);
  const float min_range2 = static_cast<float>(cfg.min_range_m * cfg.min_range_m);
  std::vector<int> beam(scan.cols(), -1);
  std::vector<int> count(model.numBeams() + 1, 0);
  for (Eigen::Index i = 0; i < scan.cols(); ++i) {
    if (removed && (*removed)[i]) continue;
    const Eigen::Vector3f p = scan.col(i).head<3>();
    if (!p.allFinite() || p.squaredNorm() < min_range2) continue;
    beam[i] = model.beamOf(p);
    if (beam[i] >= 0) ++count[beam[i] + 1];
  }
  Rings rings;
  rings.start.resize(count.size());
  std::partial_sum(count.begin(), count.end(), rings.start.begin());
  rings.points.resize(3, rings.start.back());
  std::vector<int> next(rings.start.begin(), rings.start.end() - 1);
  for (Eigen::Index i = 0; i < scan.cols(); ++i)
    if (beam[i] >= 0) rings.points.col(next[beam[i]]++) = scan.col(i).head<3>();
  return rings;
}

pcl::PointXYZI toPoint(const Eigen::Vector3f& p, int beam) {
  pcl::PointXYZI q;
  q.x = p.x();
  q.y = p.y();
  q.z = p.z();
  q.intensity = static_cast<float>(beam);
  return q;
}

// Feature selection on one ring (A-LOAM's per-sector loop).
class RingSelector {
 public:
  // `ring`: a view into the scan's rings (no copy per ring).
  RingSelector(const Eigen::Ref<const Eigen::Matrix3Xf>& ring, const FeatureConfig& cfg)
      : ring_(ring), cfg_(cfg), curvature_(ringCurvature(ring, cfg.curvature_half_window)),
        label_(ring.cols(), kNone), picked_(ring.cols(), false) {
    excludeWindowsOverGaps();
  }

  void select(int beam, ScanFeatures& out) {
    const int w = cfg_.curvature_half_window;
    const int first = w, last = static_cast<int>(ring_.cols()) - w - 1;  // inclusive
    if (last - first < cfg_.sectors_per_beam) return;
    for (int s = 0; s < cfg_.sectors_per_beam; ++s) {
      const int sp = first + (last - first) * s / cfg_.sectors_per_beam;
      const int ep = first + (last - first) * (s + 1) / cfg_.sectors_per_beam - 1;
      // Edge candidates strongest first, plane candidates flattest first: (curvature, index)
      // pairs, ordered only as far as the picking reads them (it stops after a few features),
      // where sorting each whole sector cost 7 % of the odometry's instructions. The pairs are
      // unique, so the order read is exactly the full sort's.
      edge_candidates_.clear();
      flat_candidates_.clear();
      for (int i = sp; i <= ep; ++i) {
        if (curvature_[i] > cfg_.edge_curvature_min) edge_candidates_.push_back({curvature_[i], i});
        if (curvature_[i] < cfg_.plane_curvature_max) flat_candidates_.push_back({curvature_[i], i});
      }
      pickEdges(beam, out);
      pickFlats(beam, out);
    }
    // Everything that is not an edge is a plane candidate for the map, thinned along the ring.
    Eigen::Vector3f last_kept = Eigen::Vector3f::Constant(1e30f);
    const float spacing2 = static_cast<float>(cfg_.less_flat_spacing_m * cfg_.less_flat_spacing_m);
    for (int i = first; i <= last; ++i) {
      if (label_[i] > 0 || (ring_.col(i) - last_kept).squaredNorm() < spacing2) continue;
      last_kept = ring_.col(i);
      out.less_flat.push_back(toPoint(last_kept, beam));
    }
  }

 private:
  using Candidate = std::pair<float, int>;

  // Visits `c` in `before` order, ordering it chunk by chunk as the visit proceeds, until
  // `visit` returns false.
  template <class Before, class Visit>
  static void inOrder(std::vector<Candidate>& c, Before before, Visit visit) {
    size_t ordered = 0;
    for (size_t k = 0; k < c.size(); ++k) {
      if (k == ordered) {
        const size_t next = std::min(c.size(), std::max<size_t>(2 * ordered, 32));
        if (next < c.size()) std::nth_element(c.begin() + ordered, c.begin() + next - 1, c.end(), before);
        std::sort(c.begin() + ordered, c.begin() + next, before);
        ordered = next;
      }
      if (!visit(c[k])) return;
    }
  }

  void pickEdges(int beam, ScanFeatures& out) {
    int n = 0;
    if (cfg_.less_sharp_per_sector <= 0) return;
    inOrder(edge_candidates_, std::greater<Candidate>(), [&](const Candidate& c) {
      const int i = c.second;
      if (picked_[i]) return true;
      ++n;
      label_[i] = n <= cfg_.sharp_per_sector ? kSharp : kLessSharp;
      if (label_[i] == kSharp) out.sharp.push_back(toPoint(ring_.col(i), beam));
      out.less_sharp.push_back(toPoint(ring_.col(i), beam));
      suppressNeighbours(i);
      return n < cfg_.less_sharp_per_sector;
    });
  }

  void pickFlats(int beam, ScanFeatures& out) {
    int n = 0;
    if (cfg_.flat_per_sector <= 0) return;
    inOrder(flat_candidates_, std::less<Candidate>(), [&](const Candidate& c) {
      const int i = c.second;
      if (picked_[i]) return true;
      ++n;
      label_[i] = kFlat;
      out.flat.push_back(toPoint(ring_.col(i), beam));
      suppressNeighbours(i);
      return n < cfg_.flat_per_sector;
    });
  }

  // Curvature across a gap in the ring (no return, or where two lasers share a beam index) compares
  // points that are not neighbours on a surface: such points are never features.
  void excludeWindowsOverGaps() {
    const int n = static_cast<int>(ring_.cols()), w = cfg_.curvature_half_window;
    const float cos_gap = static_cast<float>(std::cos(cfg_.max_azimuth_gap_deg * M_PI / 180.0));
    int last_gap = -n;  // index i of the last gap between points i and i+1
    std::vector<int> gap_before(n);  // the last gap at or before point i (between j and j+1, j < i)
    float norm_next = n > 0 ? ring_.col(0).head<2>().norm() : 0.0f;  // each norm computed once
    for (int i = 0; i < n; ++i) {
      gap_before[i] = last_gap;
      if (i + 1 < n) {
        const float norm_i = norm_next;
        norm_next = ring_.col(i + 1).head<2>().norm();
        if (ring_.col(i).head<2>().dot(ring_.col(i + 1).head<2>()) < cos_gap * norm_i * norm_next) last_gap = i;
      }
    }
    // Point i's window [i-w, i+w] spans a gap when one lies between i-w and i+w-1.
    for (int i = 0; i < n; ++i) {
      const int end = std::min(i + w, n - 1);
      if (gap_before[end] >= i - w) picked_[i] = true;
    }
  }

  // Features spread out: the neighbours of a picked point are not picked, unless a gap in the
  // ring (an occlusion boundary) separates them from it.
  void suppressNeighbours(int i) {
    picked_[i] = true;
    const float max_gap2 = static_cast<float>(cfg_.suppression_max_gap_m * cfg_.suppression_max_gap_m);
    const int n = static_cast<int>(ring_.cols());
    for (int dir : {1, -1}) {
      for (int l = 1; l <= cfg_.suppression_half_window; ++l) {
        const int j = i + dir * l;
        if (j < 0 || j >= n || (ring_.col(j) - ring_.col(j - dir)).squaredNorm() > max_gap2) break;
        picked_[j] = true;
      }
    }
  }

  Eigen::Ref<const Eigen::Matrix3Xf> ring_;
  const FeatureConfig& cfg_;
  Eigen::VectorXf curvature_;
  std::vector<int8_t> label_;
  std::vector<uint8_t> picked_;  // not std::vector<bool>: its bit access cost 1.5 % of the odometry
  std::vector<Candidate> edge_candidates_, flat_candidates_;
};

}  // namespace

ScanFeatures extractFeatures(const PointCloud& scan, const FeatureConfig& cfg, const std::vector<bool>* removed) {
  const Rings rings = groupByBeam(scan, cfg, removed);
  ScanFeatures out;
  out.num_points = static_cast<int>(rings.points.cols());
  for (size_t b = 0; b + 1 < rings.start.size(); ++b) {
    RingSelector(rings.points.middleCols(rings.start[b], rings.start[b + 1] - rings.start[b]), cfg)
        .select(static_cast<int>(b), out);
  }
  return out;
}

}  // namespace dlslot::odometry
