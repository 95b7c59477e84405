// The mapper's settings (config section `mapper`, documented in config/dlslot.yaml).
#pragma once

#include <string>

#include "dlslot/config.hpp"

namespace dlslot::mapper {

struct LoopConfig {
  bool enabled = true;
  // The registered clouds de-skewed with the ego's motion and put back on their rays
  // (vertical_angle_error_rad), as the odometry's features are (config/dlslot.yaml says why).
  bool correct_clouds = true;
  int rings = 20, sectors = 60;
  double max_radius_m = 50.0;
  double min_separation_m = 100.0, search_radius_m = 40.0;
  double max_descriptor_distance = 0.4;
  double registration_voxel_m = 0.5, coarse_correspondence_m = 6.0, max_correspondence_m = 2.0,
         fine_correspondence_m = 0.6;
  int submap_keyframes = 10;  // the match side of a verification: the candidate and this many keyframes either side
  double overlap_radius_m = 30.0;
  double inlier_distance_m = 0.3, support_distance_m = 1.0, min_inlier_ratio = 0.5, max_rmse_m = 0.25;
  double max_drift_fraction = 0.03;
  double ambiguity_shift_m = 4.0, ambiguity_ratio = 0.9;
  double false_loop_m = 1.0;  // an accepted loop farther than this from the truth is false (dlslot-eval's map.loops_false)
  // Registration starts besides the prior: shifted k x start_step_m along the query's x and y, k = 1..start_steps,
  // those within the drift bound.
  double start_step_m = 4.0;
  int start_steps = 2;
  // After an accepted loop, the next search is this many keyframes on (0: the following keyframes
  // each verify the place again and add their own edge).
  int quiet_keyframes = 0;
  double odometry_sigma_t = 0.02, odometry_sigma_r = 0.002;
  double loop_sigma_t = 0.1, loop_sigma_r = 0.01;
};

struct MapperConfig {
  double keyframe_distance_m = 1.0, keyframe_angle_deg = 10.0;
  double min_range_m = 2.5, max_range_m = 50.0;
  double map_voxel_m = 0.2;
  bool remove_movable = false;  // remove: movable (every track) instead of dynamic (moving tracks)
  double box_margin_m = 0.7;
  double ground_clearance_m = 0.1;
  // The config's lidar section: the scans' firing order (a moving object's points lie in its box
  // moved by its motion relative to the lidar until the instant they were fired), and how far below
  // its ray each point is stored (the loop closer's clouds may be corrected by both).
  LidarConfig lidar;
  double min_new_fraction = 0.01;  // a keyframe keeps its loop-closure cloud when this share of its points made new voxels
  int decision_delay_frames = 15, follow_frames = 15;
  double join_timeout_s = 5.0;  // live: how long a scan waits for its SLOT_STATE (and back)
  int max_backlog_keyframes = 50;  // live: keyframes that may wait for the keyframe thread (and for loop closure)
  bool idle_priority = true;       // live: the keyframe and loop-closure threads at SCHED_IDLE
  double live_cpu_share = 1.0;     // live: the most of one core each of those threads uses (idle_worker.hpp)
  LoopConfig loop;

  // Reads and checks the section; throws ConfigError naming the key and what was expected.
  static MapperConfig read(ConfigSection& section);
};

}  // namespace dlslot::mapper
