// The mapper's pipeline, LCM-free: each scan with its SLOT_STATE pose and tracks goes in; a
// keyframe is taken every keyframe_distance_m / keyframe_angle_deg; once decision_delay_frames
// newer scans have arrived its points inside the (grown, followed) boxes of moving objects are
// removed, the rest goes into the static map at the keyframe's current pose and to loop closure.
// Accepted loops re-optimize the keyframe graph; the map's voxels follow their keyframes.
#pragma once

#include <deque>
#include <map>
#include <memory>
#include <vector>

#include "mapper/loop_closer.hpp"
#include "mapper/mapper_config.hpp"
#include "mapper/track_boxes.hpp"
#include "mapper/voxel_map.hpp"

namespace dlslot::mapper {

struct MapperInput {
  int frame = 0;
  int64_t utime = 0;
  PointCloud scan;                    // lidar frame (may be empty when !needsScan(pose))
  Pose pose = Pose::Identity();       // T_world_lidar (SLOT_STATE ego pose)
  std::vector<TrackSnapshot> tracks;  // world frame
};

struct KeyframeRecord {
  int frame = 0;
  int64_t utime = 0;
  Pose odometry = Pose::Identity();  // T_world_lidar
  Pose map = Pose::Identity();       // T_map_lidar (loop-closed)
  int kept = 0, removed = 0;         // points
};

class Mapper {
 public:
  // threaded: loop closure on its own thread (live); else inline (offline, reproducible).
  Mapper(const MapperConfig& config, bool threaded);

  // Whether a scan at `pose` (T_world_lidar) becomes a keyframe: only then does add() read its
  // points, so a caller may leave MapperInput::scan empty (and not decode it) otherwise.
  bool needsScan(const Pose& pose) const;
  void add(const MapperInput& in);
  // Takes in the keyframes still waiting for their removal decision and waits for loop closure.
  void finish();

  // T_map_world: the correction of the newest optimized keyframe (identity before any loop).
  const Pose& mapFromWorld() const { return map_from_world_; }
  // Loop-closed pose of every scan seen: its keyframe's correction applied to its SLOT pose.
  std::vector<std::pair<int, Pose>> mapTrajectory() const;
  std::vector<int64_t> frameUtimes() const;
  const std::vector<KeyframeRecord>& keyframes() const { return keyframes_; }
  const VoxelMap& map() const { return map_; }
  const VoxelMap& removed() const { return removed_; }
  LoopCloser& loops() { return *loops_; }
  const LoopCloser& loops() const { return *loops_; }
  double keyframeMs() const { return keyframe_ms_; }  // total time committing keyframes here

 private:
  struct Pending {
    int frame;
    int64_t utime;
    Pose pose;
    PointCloud scan;  // cropped to [min_range, max_range]
  };
  void commit(Pending& p);
  void applyLoopResult();

  MapperConfig config_;
  TrackBoxes boxes_;
  VoxelMap map_, removed_;
  std::unique_ptr<LoopCloser> loops_;
  std::deque<Pending> pending_;
  std::vector<KeyframeRecord> keyframes_;
  std::map<int, std::pair<int64_t, Pose>> frames_;  // scan -> utime, SLOT pose
  std::optional<Pose> last_keyframe_pose_;
  Pose map_from_world_ = Pose::Identity();
  std::vector<Pose> optimized_;  // the loop closer's latest T_map_keyframe
  double keyframe_ms_ = 0;
};

}  // namespace dlslot::mapper
