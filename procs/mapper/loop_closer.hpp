// Place recognition, verification and the pose graph, on a thread of their own so that the map
// keeps up with the scans whatever a verification costs. Each keyframe (its static points in its
// own frame and its SLOT pose) gets a Scan Context; the candidates are keyframes at least
// min_separation_m back along the path and within search_radius_m of it by the current estimate;
// the best one by descriptor distance is verified (loop_verifier.hpp), and an accepted loop
// becomes a loop edge and the graph is re-optimized.
#pragma once

#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "dlslot/deskew.hpp"
#include "mapper/idle_worker.hpp"
#include "mapper/loop_verifier.hpp"
#include "mapper/mapper_config.hpp"
#include "mapper/pose_graph.hpp"
#include "mapper/scan_context.hpp"

namespace dlslot::mapper {

struct KeyframeInput {
  int id = 0;     // 0, 1, 2, ... in order
  int frame = 0;  // scan index
  Pose odometry = Pose::Identity();  // T_world_lidar from SLOT_STATE
  PointCloud points;                 // static points, lidar frame, as stored
  BodyTwist twist;                   // the ego's motion over the keyframe's sweep (for de-skewing)
  bool keep_cloud = true;            // false: used as a query now, not kept as a candidate (a place already held)
  bool last = false;                 // the run's last keyframe: its nearest candidate is always verified
};

struct LoopEvent {
  int query_keyframe = 0, match_keyframe = 0;
  int query_frame = 0, match_frame = 0;
  double descriptor_distance = 1;
  LoopVerdict verdict;
};

class LoopCloser {
 public:
  // threaded: verification on a worker thread (live; idle_priority: at SCHED_IDLE, idle_worker.hpp)
  // with at most `capacity` keyframes waiting (add() blocks beyond); else inline in add()
  // (offline, reproducible).
  // lidar: how the scans were taken (for LoopConfig::correct_clouds).
  LoopCloser(const LoopConfig& config, const LidarConfig& lidar, bool threaded, size_t capacity = 64,
             bool idle_priority = false, double cpu_share = 1.0);
  ~LoopCloser();
  LoopCloser(const LoopCloser&) = delete;
  LoopCloser& operator=(const LoopCloser&) = delete;

  void add(KeyframeInput keyframe);
  // Waits until every keyframe added so far is handled (at normal priority).
  void drain();
  const IdleWorker& worker() const { return worker_; }
  IdleWorker& worker() { return worker_; }

  // The optimized poses T_map_keyframe of keyframes 0..n-1, when they changed since the last call.
  std::optional<std::vector<Pose>> takeOptimizedPoses();
  // Loop candidates verified since the last call.
  std::vector<LoopEvent> takeEvents();
  // Every verified candidate so far.
  std::vector<LoopEvent> allEvents() const;
  int accepted() const;
  int rejected() const;
  // CPU milliseconds per keyframe spent here (correction, sampling, descriptor, search, verification,
  // optimization).
  std::vector<double> timesMs() const;

 private:
  void process(KeyframeInput kf);

  struct Keyframe {
    int frame = 0;
    Pose odometry;
    double path_m = 0;
    ScanContext descriptor;
    PointCloud cloud;  // downsampled to registration_voxel_m (and corrected); empty when not kept
    bool candidate = true;  // its cloud and descriptor are kept
  };
  LoopConfig config_;
  LidarConfig lidar_;
  ScanContextParams sc_params_;
  // Owned by the worker.
  std::vector<Keyframe> keyframes_;
  PoseGraph graph_;
  int quiet_until_ = -1;  // no search before this keyframe (just after an accepted loop)
  int last_accepted_ = -2;  // the query keyframe of the last accepted loop

  mutable std::mutex mutex_;
  std::optional<std::vector<Pose>> optimized_;
  std::vector<LoopEvent> new_events_, events_;
  std::vector<double> times_ms_;
  IdleWorker worker_;  // last: its thread stops before the state above goes
};

// One point per voxel (the first), for registration clouds.
PointCloud voxelDownsample(const PointCloud& points, double voxel_m);

}  // namespace dlslot::mapper
