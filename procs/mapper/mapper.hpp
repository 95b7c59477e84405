// The mapper's pipeline, LCM-free: each scan with its SLOT_STATE pose and tracks goes in; a
// keyframe is taken every keyframe_distance_m / keyframe_angle_deg; once decision_delay_frames
// newer scans have arrived its points inside the (grown, followed) boxes of moving objects are
// removed, the rest goes into the static map at the keyframe's current pose and to loop closure.
// Accepted loops re-optimize the keyframe graph; the map's voxels follow their keyframes.
//
// Live, the costly part (decoding a keyframe's scan, the removal, the map, loop closure) runs on
// threads at idle priority (idle_worker.hpp): add() itself only books the frame. When the
// keyframe thread falls behind by max_backlog_keyframes, a scan that would be a keyframe is not
// taken (counted: keyframesDeferred()); the next scan is considered again, so keyframes only grow
// further apart while the machine has no idle time, and memory stays bounded.
#pragma once

#include <atomic>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <vector>

#include "dlslot/deskew.hpp"
#include "mapper/idle_worker.hpp"
#include "mapper/loop_closer.hpp"
#include "mapper/mapper_config.hpp"
#include "mapper/track_boxes.hpp"
#include "mapper/voxel_map.hpp"

namespace dlslot::mapper {

// Thrown by a ScanLoader when the scan's points do not decode (reason: a short key for counters).
struct ScanRefused : std::runtime_error {
  ScanRefused(std::string reason_key, const std::string& detail) : std::runtime_error(detail), reason(std::move(reason_key)) {}
  std::string reason;
};
// A scan's points (lidar frame), decoded on demand: only a keyframe's scan is ever decoded, and
// live on the keyframe thread, not on the thread that receives the messages.
using ScanLoader = std::function<PointCloud()>;

struct MapperInput {
  int frame = 0;
  int64_t utime = 0;
  PointCloud scan;                    // lidar frame; ignored when load_scan is set
  ScanLoader load_scan;               // if set: called for keyframes only, may throw ScanRefused
  Pose pose = Pose::Identity();       // T_world_lidar (SLOT_STATE ego pose)
  std::vector<TrackSnapshot> tracks;  // world frame
};

struct KeyframeRecord {
  int frame = 0;
  int64_t utime = 0;
  Pose odometry = Pose::Identity();  // T_world_lidar
  Pose map = Pose::Identity();       // T_map_lidar (loop-closed)
  int kept = 0, removed = 0;         // points
  // T_map_lidar the keyframe's points were put in the map with: the voxel grid they were counted on
  // (dlslot-eval --map counts the truth on it; a loop correction moves `map`, not this).
  Pose inserted = Pose::Identity();
};

// What MAP_STATE reports, read while the keyframe thread works.
struct MapperSnapshot {
  Pose map_from_world = Pose::Identity();
  int keyframes = 0;
  size_t map_voxels = 0, removed_voxels = 0;
  int keyframes_deferred = 0;  // scans not taken as keyframes because the keyframe thread was behind
  size_t backlog = 0;          // keyframes waiting for the keyframe thread
};

class Mapper {
 public:
  // threaded: keyframes and loop closure on threads of their own at idle priority (live); else
  // inline (offline, reproducible).
  Mapper(const MapperConfig& config, bool threaded);
  ~Mapper();

  // Whether a scan at `pose` (T_world_lidar) is far enough from the last keyframe to be one.
  bool needsScan(const Pose& pose) const;
  void add(MapperInput in);
  // Takes in the keyframes still waiting for their removal decision and the run's last scan as a
  // keyframe of its own (the scans after the last keyframe would otherwise follow SLOT's drift
  // from it, and the end of a drive is where a loop closes: it gets its own loop edge), and waits
  // (at normal priority) until the keyframe thread and loop closure have caught up.
  void finish();

  MapperSnapshot snapshot() const;
  // Scans whose points did not decode (their keyframe skipped), since the last call.
  std::vector<ScanRefused> takeRefusedScans();
  // Errors the keyframe thread caught, since the last call.
  std::vector<std::string> takeErrors();

  // After finish():
  // Loop-closed pose of every scan seen: its keyframe's correction applied to its SLOT pose.
  std::vector<std::pair<int, Pose>> mapTrajectory() const;
  std::vector<int64_t> frameUtimes() const;
  const std::vector<KeyframeRecord>& keyframes() const { return keyframes_; }
  const VoxelMap& map() const { return map_; }
  const VoxelMap& removed() const { return removed_; }
  Pose mapFromWorld() const;
  LoopCloser& loops() { return *loops_; }
  const LoopCloser& loops() const { return *loops_; }
  double keyframeMs() const { return keyframe_ms_; }  // total CPU time committing keyframes (decoding included)
  int keyframesDeferred() const { return deferred_; }
  const MapperConfig& config() const { return config_; }
  // Why a worker thread does not run at idle priority when asked to (empty: it does).
  std::vector<std::string> priorityErrors() const;
  size_t maxBacklog() const { return committer_->maxBacklog(); }
  // CPU milliseconds used so far by the keyframe and loop-closure threads (0 inline).
  double workerCpuMs() const { return committer_->cpuMs() + loops_->worker().cpuMs(); }

 private:
  struct Pending {
    int frame;
    int64_t utime;
    Pose pose;
    PointCloud scan;        // when given decoded
    ScanLoader load_scan;   // else this
    bool last = false;      // the run's last scan, taken as a keyframe by finish()
  };
  // On the caller's thread: the removal boxes of a keyframe, lidar frame, with their motion.
  std::vector<MovingBox> lidarBoxes(const Pending& p) const;
  // On the caller's thread: the ego's motion over the keyframe's sweep, from its neighbouring scans.
  BodyTwist egoTwist(const Pending& p) const;
  // On the keyframe thread: decode, crop, remove what is inside `boxes` (lidar frame), insert;
  // the kept points go on to the loop closer with `twist`, which corrects them for registration.
  // The map keeps the points as stored, where its removal and the evaluation's truth test them
  // (each box at each point's firing time, each map point one of its scan's).
  void commit(Pending& p, const std::vector<MovingBox>& boxes, const BodyTwist& twist);
  void applyLoopResult();

  MapperConfig config_;
  // The caller's thread.
  TrackBoxes boxes_;
  std::deque<Pending> pending_;
  std::map<int, std::pair<int64_t, Pose>> frames_;  // scan -> utime, SLOT pose
  std::optional<Pose> last_keyframe_pose_;
  std::optional<Pending> last_scan_;  // the latest scan not taken as a keyframe (finish() takes it)
  int deferred_ = 0;
  // The keyframe thread (read by the caller after finish()).
  VoxelMap map_, removed_;
  std::vector<KeyframeRecord> keyframes_;
  std::vector<Pose> optimized_;  // the loop closer's latest T_map_keyframe
  double keyframe_ms_ = 0;
  // Shared.
  mutable std::mutex mutex_;
  Pose map_from_world_ = Pose::Identity();
  std::atomic<int> keyframe_count_{0};
  std::atomic<size_t> map_voxels_{0}, removed_voxels_{0};
  std::vector<ScanRefused> refused_;
  std::unique_ptr<LoopCloser> loops_;
  std::unique_ptr<IdleWorker> committer_;  // last: stops (finishing its jobs) before the rest goes
};

}  // namespace dlslot::mapper
