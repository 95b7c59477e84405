// What one bird's-eye image shows: a plain snapshot of one frame, independent of LCM, so the live
// node, the offline log renderer, tests and benchmarks all draw through the same function.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "dlslot/types.hpp"

namespace dlslot::renderer {

// One object as the sliding-window optimization estimates it at this frame (world frame).
struct TrackState {
  int id = -1;
  std::string type;
  Pose pose = Pose::Identity();  // T_world_object: box centre and heading
  Eigen::Vector3d size = Eigen::Vector3d::Zero();      // l w h
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  // world frame, m/s
  bool is_dynamic = false;
  std::vector<Eigen::Vector3d> trail;  // world positions at earlier frames, oldest first
};

// One detection's assignment by the tracker (paper III-B): where the trajectory was predicted
// (eq. 3) and which track took the detection.
struct AssociationMark {
  int detection_index = -1;
  int track_id = -1;
  bool initialized = false;
  std::optional<Eigen::Vector3d> predicted_lidar;  // predicted position, lidar frame of this scan
};

// Per-stage wall times one module reported for this frame.
struct ModuleTiming {
  std::string module;                                // "odometry", "tracker", "backend"
  std::vector<std::pair<std::string, double>> stages;  // (stage, ms); "total" when reported
};

struct RenderInput {
  int frame = -1;
  int64_t utime = 0;
  double time_s = 0.0;  // since the first frame of the run

  // Each layer says whether its message arrived; a missing layer is drawn as "missing", never
  // confused with an empty one (a scan with no detections).
  bool has_scan = false;
  PointCloud scan;  // lidar frame
  bool has_detections = false;
  std::vector<Box> detections;  // lidar frame
  bool has_ground_truth = false;
  std::vector<Box> gt_boxes;  // lidar frame, id = label track id
  bool has_associations = false;
  std::vector<AssociationMark> associations;
  bool has_tracks = false;
  std::vector<TrackState> tracks;
  std::string slot_mode;  // backend mode when SLOT_STATE arrived

  // Ego positions so far (world frame, frame order, this frame included when known).
  std::vector<Eigen::Vector3d> odometry_path, slot_path, gt_path;
  // T_world_lidar of this scan, used to place lidar-frame layers in the world and world-frame
  // layers around the ego; from the best source available (slot > odometry > ground truth).
  std::optional<Pose> ego_pose;
  std::string ego_source;

  // What ODOMETRY said about its filter (paper III-D): whether it removed points inside the
  // detections (A-LOAM*) and how many. Without ODOMETRY the image shows what A-LOAM* would remove.
  bool has_odometry = false;
  bool odometry_filtered = false;
  int odometry_removed = 0;
  std::vector<ModuleTiming> timings;
};

}  // namespace dlslot::renderer
