// What the backend takes and gives per frame, as plain types (the node converts messages).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "backend/object_registration.hpp"
#include "backend/odometry_consistency.hpp"
#include "backend/se3.hpp"
#include "backend/side_ends.hpp"
#include <array>
#include <memory>
#include "dlslot/track_lifecycle.hpp"
#include "dlslot/types.hpp"

namespace dlslot::backend {

struct OdometryInput {
  Pose pose = Pose::Identity();   // T_world_lidar of the frame, as the odometry chains it
  Pose delta = Pose::Identity();  // T_prev_cur: the motion since the previous frame (eq. 8's T)
  Matrix6 covariance = Matrix6::Identity();  // of delta, (tx ty tz rx ry rz)
  bool ok = true;                 // false: the odometry fell back to a prediction
};

// One associated detection (paper III-B): b_t and the tracker's view of its trajectory.
struct ObservationInput {
  int track_id = -1;
  bool initialized = false;   // the trajectory is in O_init (>= g observations)
  Box box;                    // b_t: lidar frame of this scan (centre, size l w h, yaw, type)
  bool dynamic_guess = false; // the tracker's preliminary static/dynamic guess
  bool confirmed = true;      // the tracker's lifecycle confirmed the track (tentative ones stay out of the graph)
  double confidence = 1.0;    // the track's confidence after this detection, [0, 1]
  // The object's points in this scan (lidar frame; selected by its box from BackendInput::scan),
  // when the scan arrived: per-object registration (object_registration.hpp).
  std::shared_ptr<const ObjectPoints> points;
  // Which of its ends along the box's heading the scan saw whole (side_ends.hpp: endsSeen).
  EndsSeen ends_seen;
};

struct BackendInput {
  int frame = 0;
  int64_t utime = 0;
  std::optional<OdometryInput> odometry;  // none: no ODOMETRY arrived for this frame
  bool associations_missing = false;      // no ASSOCIATIONS arrived: no objects this frame
  std::vector<ObservationInput> observations;
  // This frame's scan (lidar frame) when the registration reads scans: each registered
  // observation's points are cropped from it (attachObjectPoints), and those of the moving
  // vehicles the detector missed in it, where their chains predict them. Without it, the points
  // the observations carry.
  std::shared_ptr<const PointCloud> scan;
};

struct TrackEstimate {
  int id = -1;
  std::string type;
  Pose pose = Pose::Identity();  // T_world_object at the newest frame
  Eigen::Vector3d size = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();          // world frame, m/s
  // Of the velocity, world frame, (m/s)^2; for a static track (still by its model, velocity zero)
  // its window's motion evidence about zero. Zero when covariances are not computed.
  Eigen::Matrix3d velocity_covariance = Eigen::Matrix3d::Zero();
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  // world frame, rad/s
  bool dynamic = false;
  Matrix6 covariance = Matrix6::Zero();  // tangent of the PoseManifold (world-frame dt, dtheta)
  int age = 0;               // frames since first seen
  int num_observations = 0;  // observations in the window
  int last_seen_frame = -1;
  TrackStatus status = TrackStatus::Confirmed;  // confirmed when seen this frame, else coasting
  double confidence = 1.0;   // [0, 1], the tracker's lifecycle confidence at its latest detection
};

struct SolveStats {
  double solve_ms = 0, marginalize_ms = 0, covariance_ms = 0, total_ms = 0;
  int iterations = 0;
  double initial_cost = 0, final_cost = 0;
  int num_blocks = 0, num_factors = 0;
  int prior_dim = 0;  // tangent dimension of the marginalization prior
};

struct SmoothedPose {
  int frame = 0;
  int64_t utime = 0;
  Pose pose = Pose::Identity();
};

struct BackendOutput {
  int frame = 0;
  int64_t utime = 0;
  Pose ego_pose = Pose::Identity();  // newest optimized T_world_lidar
  Matrix6 ego_covariance = Matrix6::Zero();
  std::optional<SmoothedPose> smoothed;  // the frame that left the window with this solve
  bool odometry_missing = false;
  bool associations_missing = false;
  // This frame's odometry factor against the motion its landmarks and objects imply
  // (odometry_consistency.hpp): untested, consistent, or down-weighted.
  OdometryCheck odometry_check;
  std::vector<TrackEstimate> tracks;
  SolveStats stats;
  int static_to_dynamic = 0;  // landmarks that turned dynamic this frame
  // Per-object registrations this frame by outcome (RegistrationOutcome), and objects of a
  // registered class whose previous scan's points were missing (new, or missed last frame).
  std::array<int, kNumRegistrationOutcomes> registrations{};
  int registration_no_previous = 0;
  // Over this frame's registrations: the objects' points (previous scan) and the squared RMS
  // point-to-plane residual, summed (to compare the simulator's objects with real ones).
  int64_t registration_points = 0;
  double registration_residual_sq = 0;
  // Scan pairs of this frame whose face's speed along the line of sight was measured
  // (line_of_sight.hpp).
  int line_of_sight_pairs = 0;
  // And those whose side's ends gave its speed along its heading (side_ends.hpp).
  int side_pairs = 0;
  // Vehicles the detector missed in this scan whose points, cropped where their chains predict
  // them, were measured.
  int missed_vehicles_measured = 0;
};

}  // namespace dlslot::backend
