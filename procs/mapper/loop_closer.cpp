#include "mapper/loop_closer.hpp"

#include <memory>

#include "dlslot/cpu_clock.hpp"
#include "dlslot/vertical_angle.hpp"
#include "dlslot/voxel_key.hpp"

namespace dlslot::mapper {

PointCloud voxelDownsample(const PointCloud& points, double voxel_m) {
  // An open-addressing set of the voxel keys seen (linear probing, at most half full): a keyframe's
  // ~100 k points cost one probe each, where std::unordered_set allocated a node per voxel.
  size_t capacity = 16;
  while (capacity < 2 * static_cast<size_t>(points.cols())) capacity <<= 1;
  constexpr uint64_t kEmpty = ~uint64_t{0};  // voxelKey uses 63 bits: never this
  std::vector<uint64_t> table(capacity, kEmpty);
  const uint64_t mask = capacity - 1;
  std::vector<Eigen::Index> keep;
  uint64_t previous = kEmpty;  // consecutive points of a ring often share a cell: one look-up for the run
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const uint64_t key = voxelKey(points.col(i).head<3>().cast<double>(), voxel_m);
    if (key == previous) continue;
    previous = key;
    for (uint64_t h = (key * 0x9E3779B97F4A7C15ull) >> 20 & mask;; h = (h + 1) & mask) {
      if (table[h] == key) break;
      if (table[h] == kEmpty) {
        table[h] = key;
        keep.push_back(i);
        break;
      }
    }
  }
  PointCloud out(4, static_cast<Eigen::Index>(keep.size()));
  for (size_t k = 0; k < keep.size(); ++k) out.col(static_cast<Eigen::Index>(k)) = points.col(keep[k]);
  return out;
}

LoopCloser::LoopCloser(const LoopConfig& config, const LidarConfig& lidar, bool threaded, size_t capacity,
                       bool idle_priority, double cpu_share)
    : config_(config), lidar_(lidar), worker_("loop closure", threaded, capacity, idle_priority, cpu_share) {
  sc_params_.rings = config.rings;
  sc_params_.sectors = config.sectors;
  sc_params_.max_radius_m = config.max_radius_m;
}

LoopCloser::~LoopCloser() = default;

void LoopCloser::add(KeyframeInput kf) {
  // std::function needs a copyable job: the keyframe's points travel in a shared pointer.
  auto shared = std::make_shared<KeyframeInput>(std::move(kf));
  worker_.post([this, shared] { process(std::move(*shared)); });
}

void LoopCloser::drain() { worker_.drain(); }

void LoopCloser::process(KeyframeInput in) {
  // CPU time of this thread: at idle priority the wall time mostly counts waiting for a core.
  const double start = threadCpuMs();
  Keyframe kf;
  kf.frame = in.frame;
  kf.odometry = in.odometry;
  // Keyframes tens of metres apart, driven at different speeds and turn rates, are registered to
  // each other: each point is put back on its ray (vertical_angle.hpp: uncorrected, the two sides'
  // ground cones fit best tilted) and then into the frame of the scan's reference instant
  // (deskew.hpp: skewed, the two sides differ by a shear that registration reads as a rotation).
  // Before the sampling: the urban-loop table in docs/mapping.md was measured so (corrected after
  // it, the one point kept per voxel changes and seed 10's marginal loop was refused).
  if (config_.correct_clouds) {
    correctElevation(in.points, lidar_.vertical_angle_error_rad);
    deskew(in.points, lidar_.sweep, in.twist);
  }
  kf.cloud = voxelDownsample(in.points, config_.registration_voxel_m);
  kf.descriptor = makeScanContext(kf.cloud, sc_params_);
  kf.candidate = in.keep_cloud;
  const int id = static_cast<int>(keyframes_.size());
  if (id > 0) {
    const Keyframe& prev = keyframes_.back();
    const Pose T_ab = prev.odometry.inverse() * kf.odometry;
    const double d = T_ab.translation().norm();
    kf.path_m = prev.path_m + d;
    // The node starts where the current correction puts it: the previous node's pose times the
    // odometry's motion.
    graph_.addNode(graph_.pose(id - 1) * T_ab);
    Vector6d sigma;
    const double st = 0.01 + config_.odometry_sigma_t * d, sr = 0.001 + config_.odometry_sigma_r * d;
    sigma << st, st, st, sr, sr, sr;
    graph_.addOdometryEdge(id - 1, id, T_ab, sigma);
  } else {
    graph_.addNode(kf.odometry);
  }
  keyframes_.push_back(std::move(kf));
  const Keyframe& q = keyframes_.back();

  std::optional<LoopEvent> event;
  if (config_.enabled && id >= quiet_until_) {
    const Pose T_q = graph_.pose(id);
    // Two ways to a candidate: the best Scan Context among the keyframes near the current
    // estimate (a place seen again from anywhere on it), and the nearest keyframe by position
    // (LIO-SAM's radius search: a place passed again tens of metres away, where an egocentric
    // descriptor no longer matches but the scans still overlap). Both lie at least
    // min_separation_m back along the path; the descriptor's one is verified first.
    int best = -1, nearest = -1;
    ScanContextMatch best_match;
    double nearest_m = config_.search_radius_m;
    for (int j = 0; j < id; ++j) {
      const Keyframe& c = keyframes_[j];
      if (q.path_m - c.path_m < config_.min_separation_m) break;  // path_m grows with j
      if (!c.candidate) continue;
      const double d = (graph_.pose(j).translation() - T_q.translation()).norm();
      if (d > config_.search_radius_m) continue;
      if (d <= nearest_m) {
        nearest_m = d;
        nearest = j;
      }
      const ScanContextMatch m = compare(q.descriptor, c.descriptor);
      if (m.distance < best_match.distance) {
        best_match = m;
        best = j;
      }
    }
    if (!(best >= 0 && best_match.distance <= config_.max_descriptor_distance)) best = -1;
    // A nearest-keyframe candidate is verified every other keyframe (the query moves on by
    // metres between them; verification is the costly part).
    // Right after an accepted loop the next keyframe is verified too: it sees the same place, and
    // each query's own registration is another loop edge (their errors partly average, and the
    // keyframes at the end of a drive get a constraint of their own); so is the run's last one.
    const bool follows_loop = last_accepted_ == id - 1 || in.last;
    const int candidate = best >= 0 ? best : (nearest >= 0 && (id % 2 == 0 || follows_loop) ? nearest : -1);
    if (candidate >= 0) {
      const Keyframe& c = keyframes_[candidate];
      const Pose T_c = graph_.pose(candidate);
      const Pose prior = T_c.inverse() * T_q;
      // Both sides are local maps, each in its own keyframe's frame: the candidate and its
      // neighbours either side, the query and the keyframes just before it. A place passed again
      // tens of metres off (urban-loop ends 35 m short of its start) overlaps only at range, where
      // one scan is sparse: the neighbours give the registration more of the shared street.
      auto localMap = [&](int centre, int lo, int hi) {
        const Pose T_centre_inv = graph_.pose(centre).inverse();
        std::vector<PointCloud> parts;
        Eigen::Index n = 0;
        for (int j = lo; j <= hi; ++j) {
          const Pose T_cj = T_centre_inv * graph_.pose(j);
          PointCloud part = keyframes_[j].cloud;
          for (Eigen::Index i = 0; i < part.cols(); ++i)
            part.col(i).head<3>() = (T_cj * part.col(i).head<3>().cast<double>()).cast<float>();
          n += part.cols();
          parts.push_back(std::move(part));
        }
        PointCloud out(4, n);
        n = 0;
        for (const PointCloud& part : parts) {
          out.middleCols(n, part.cols()) = part;
          n += part.cols();
        }
        return voxelDownsample(out, config_.registration_voxel_m);
      };
      int hi = std::min(id - 1, candidate + config_.submap_keyframes);
      while (hi > candidate && q.path_m - keyframes_[hi].path_m < config_.min_separation_m) --hi;
      const PointCloud submap = localMap(candidate, std::max(0, candidate - config_.submap_keyframes), hi);
      const PointCloud query_map = localMap(id, std::max(hi + 1, id - config_.submap_keyframes), id);
      LoopEvent e;
      e.query_keyframe = id;
      e.match_keyframe = candidate;
      e.query_frame = q.frame;
      e.match_frame = c.frame;
      e.descriptor_distance = compare(q.descriptor, c.descriptor).distance;
      e.verdict = verifyLoop(query_map, submap, prior, q.path_m - c.path_m, config_);
      if (e.verdict.accepted) {
        Vector6d sigma;
        sigma << config_.loop_sigma_t, config_.loop_sigma_t, config_.loop_sigma_t, config_.loop_sigma_r,
            config_.loop_sigma_r, config_.loop_sigma_r;
        graph_.addLoopEdge(candidate, id, e.verdict.registration.T_match_query, sigma);
        graph_.optimize();
        // quiet_keyframes > 0: the next loop is looked for that many keyframes on (neighbours of an
        // accepted loop repeat it); 0: every following keyframe may add its own edge.
        quiet_until_ = id + config_.quiet_keyframes;
        last_accepted_ = id;
      }
      event = e;
    }
  }
  if (!keyframes_[id].candidate) {  // a place already held: its cloud served this query only
    keyframes_[id].cloud.resize(4, 0);
    keyframes_[id].descriptor = ScanContext();
  }
  const double ms = threadCpuMs() - start;
  std::lock_guard<std::mutex> lock(mutex_);
  times_ms_.push_back(ms);
  if (event) {
    new_events_.push_back(*event);
    events_.push_back(*event);
  }
  if (event && event->verdict.accepted) optimized_ = graph_.poses();
}

std::optional<std::vector<Pose>> LoopCloser::takeOptimizedPoses() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::optional<std::vector<Pose>> out;
  out.swap(optimized_);
  return out;
}

std::vector<LoopEvent> LoopCloser::takeEvents() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<LoopEvent> out;
  out.swap(new_events_);
  return out;
}

std::vector<LoopEvent> LoopCloser::allEvents() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return events_;
}

int LoopCloser::accepted() const {
  std::lock_guard<std::mutex> lock(mutex_);
  int n = 0;
  for (const LoopEvent& e : events_) n += e.verdict.accepted;
  return n;
}

int LoopCloser::rejected() const {
  std::lock_guard<std::mutex> lock(mutex_);
  int n = 0;
  for (const LoopEvent& e : events_) n += !e.verdict.accepted;
  return n;
}

std::vector<double> LoopCloser::timesMs() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return times_ms_;
}

}  // namespace dlslot::mapper
