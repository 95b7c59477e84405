// The odometry of DL-SLOT's front end (paper III-D, A-LOAM): one call per scan.
#pragma once

#include <string>

#include "dlslot/convert.hpp"
#include "dlslot/types.hpp"
#include "local_map.hpp"
#include "odometry_config.hpp"
#include "scan_to_scan.hpp"

namespace dlslot::odometry {

enum class Status {
  Ok,
  FallbackFewPoints,    // too few points or features: constant-velocity prediction
  FallbackSolveFailed,  // a registration failed or jumped: constant-velocity prediction
  FirstFrame,           // identity pose, nothing to register against
};

// How the map registration constrained the translation (degeneracy.hpp), and what was done.
enum class Degeneracy {
  None,          // every direction constrained (or nothing registered)
  Confirmed,     // a weak direction, and scan-to-scan agreed with the map registration along it
  Reanchored,    // scan-to-scan disagreed (along a weak direction, or on a periodic check): the
                 // motion is scan-to-scan's, the map starts over
  Unchecked,     // a weak direction, and scan-to-scan could not check it (failed or as weak)
  Suspected,     // scan-to-scan disagreed once: the next scan is checked too, a second
                 // disagreement the same way re-anchors
};

struct OdometryResult {
  int frame = 0;
  Status status = Status::Ok;
  std::string status_text;         // why, when status != Ok
  bool detections_used = false;    // points inside detected boxes were removed (A-LOAM*)
  Pose T_world_lidar = Pose::Identity();
  Pose delta = Pose::Identity();   // T_prev_cur
  Matrix6d covariance = Matrix6d::Identity();  // of delta, tangent (t, rotation), m and rad
  double min_eigenvalue = 0.0;     // of the scan-to-map normal matrix
  // The translation's information per direction (ascending) and the weakest direction (lidar
  // frame) of the map registration, and whether that direction was weak and checked.
  Eigen::Vector3d translation_information = Eigen::Vector3d::Zero();
  Eigen::Vector3d weak_direction = Eigen::Vector3d::Zero();
  Degeneracy degeneracy = Degeneracy::None;
  double check_disagreement_m = 0.0;  // scan-to-scan minus scan-to-map along weak_direction
  double check_chi2 = 0.0;            // ...its chi-square (1 dof) against both covariances
  Eigen::Vector3d check_direction = Eigen::Vector3d::Zero();  // the direction compared (lidar frame)
  bool velocity_checked = false;      // scan-to-scan checked the map registration on this scan
  int motion_hypotheses = 0;          // ...and searched this many motion hypotheses (0: none)
  int num_points_in = 0;
  int num_points_removed = 0;
  int num_edge = 0, num_plane = 0;            // sharp and flat features
  int num_map_edge = 0, num_map_plane = 0;    // local map used for scan-to-map
  int num_correspondences = 0;                // scan-to-map, last search
  double residual_mean = 0.0;                 // scan-to-map inliers, m
  StageTimings timings;                       // features, scan_to_scan, scan_to_map, total (ms)
  // Inside those stages, CPU ms of the calling thread: box_removal, feature_extraction,
  // s2s_index (the previous scan's grids, built when scan-to-scan runs), s2s_match, s2s_solve,
  // s2m_downsample, s2m_match, s2m_solve, map_update, s2s_reference (keeping this scan for the
  // next). For benchmarks; not published.
  StageTimings detail;
};

class LidarOdometry {
 public:
  explicit LidarOdometry(OdometryConfig cfg = {});

  // One scan: remove the points inside its detected boxes (A-LOAM* mode, when `detections_available`),
  // extract edge and plane features, register them to the previous scan starting from the
  // constant-velocity guess, refine against the local map, and add them to the map. A scan
  // with too few features or a failed solve gets the constant-velocity prediction, flagged.
  OdometryResult process(const Frame& frame, bool detections_available = true);

  // Forget everything (a new sequence).
  void reset();
  const OdometryConfig& config() const { return cfg_; }
  const LocalMap& map() const { return map_; }

 private:
  void fallBack(Status status, const std::string& why, const Pose& prediction, OdometryResult& out);

  OdometryConfig cfg_;
  LocalMap map_;
  ScanReference reference_;                    // the last registered scan's features
  Pose T_world_reference_ = Pose::Identity();  // ...and its pose
  Pose T_world_last_ = Pose::Identity();       // the last published pose
  Pose velocity_ = Pose::Identity();           // motion per frame: constant-velocity model
  bool started_ = false;
  bool moving_ = false;                        // velocity_ comes from a registration
  int fallbacks_ = 0;                          // consecutive fallback frames (fallback_motion.hpp)
  Pose registered_velocity_ = Pose::Identity();  // velocity_ at the last registration (never decayed)
  int last_index_ = 0;                         // frame index of the last scan
  int frames_since_check_ = 0;                 // map registrations since scan-to-scan last checked one
  double pending_disagreement_m_ = 0.0;        // the last check disagreed by this (0: it did not)
};

}  // namespace dlslot::odometry
