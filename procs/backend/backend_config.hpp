// The backend's settings (config/dlslot.yaml, section `backend`): window, modes, the
// covariances of eq. 12 per factor type, robust loss, static/dynamic decision, solver.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "backend/object_registration.hpp"
#include "backend/odometry_consistency.hpp"
#include "backend/se3.hpp"
#include "dlslot/config.hpp"
#include "dlslot/sweep_timing.hpp"

namespace dlslot::backend {

// slot: ego poses, landmarks and objects estimated jointly (DL-SLOT). two-stage: ego poses held
// at the odometry's, objects estimated alone (the decoupled baseline). odometry-only: ego poses
// from the odometry, no objects (A-LOAM*).
enum class Mode { kSlot, kTwoStage, kOdometryOnly };
Mode parseMode(const std::string& name);  // throws std::invalid_argument
std::string toString(Mode mode);

struct BackendConfig {
  Mode mode = Mode::kSlot;
  int window_size = 10;  // k frames

  // Standard deviations [tx ty tz (m), rx ry rz (rad)] of each factor's residual; the
  // information matrix is diag(sigma)^-2 (the Sigma of eq. 12).
  // Boxes carry no roll or pitch and a loose height, hence the large z, rx, ry sigmas of the
  // (landmark) observations.
  Vector6 odometry_sigma = (Vector6() << 0.02, 0.02, 0.02, 0.0003, 0.0003, 0.0003).finished();
  Vector6 observation_sigma = (Vector6() << 0.25, 0.15, 0.3, 0.3, 0.3, 0.1).finished();
  Vector6 landmark_sigma = (Vector6() << 0.15, 0.1, 0.3, 0.3, 0.3, 0.05).finished();
  Vector6 pose_change_sigma = (Vector6() << 0.02, 0.02, 0.02, 0.005, 0.005, 0.005).finished();
  Vector6 constant_velocity_sigma = (Vector6() << 0.05, 0.03, 0.02, 0.005, 0.005, 0.0005).finished();
  // Second difference of a dynamic object's per-frame translation (constant_acceleration_factor.hpp),
  // x y z in m; eq. 11's constant_velocity_sigma then bounds the acceleration itself.
  Eigen::Vector3d constant_acceleration_sigma = Eigen::Vector3d(0.005, 0.005, 0.005);
  // Marginalize the constant-acceleration factors of a leaving pose change into the prior (the
  // acceleration survives the window's slide) instead of dropping them.
  bool marginalize_acceleration = false;
  Vector6 first_pose_sigma = (Vector6() << 1e-3, 1e-3, 1e-3, 1e-4, 1e-4, 1e-4).finished();
  // The vehicle motion prior on every pose change of a vehicle (vehicle_motion_factor.hpp):
  // sigmas of its lateral and vertical translation (m) and roll and pitch (rad) per frame, and
  // the classes it applies to.
  Eigen::Vector4d vehicle_motion_sigma = Eigen::Vector4d(0.02, 0.02, 0.002, 0.002);
  std::vector<std::string> vehicle_types = {"Car", "Van", "Truck", "Tram", "Cyclist"};
  // The RMS acceleration of moving vehicles (m/s^2), sideways and along. A vehicle's chain starts
  // straight: the yaw rate of its first pose change is zero-mean with sigma this over its speed
  // (vehicle_motion_factor.hpp). A registered velocity of t seconds ago, and a coasting track's
  // velocity last seen t seconds ago, may have changed by this x t (registered_velocity.hpp). 0: none
  // of these.
  double vehicle_acceleration = 0.0;
  // How fast a vehicle's sideways acceleration may build (m/s^3). Eq. 11's yaw sigma for a vehicle
  // is this x dt^2 over its speed: a turn's yaw rate is its sideways acceleration over its speed,
  // so a car turning in at 5 m/s changes its yaw rate five times faster than one changing lanes at
  // 25 m/s. 0: constant_velocity_sigma's rz for every class.
  double vehicle_lateral_jerk = 0.0;
  // A detector's heading is as good as its class lets it be: per class, the rz sigma of its
  // boxes when that is more than observation_sigma's (landmark_sigma's) rz.
  std::map<std::string, double> heading_sigma_by_type;
  // A detector's box position error grows with range (fewer points on the object): the
  // translation sigmas of (landmark) observations are the ones above times (1 + this x range in
  // m); 0 keeps them constant.
  double observation_sigma_growth_per_m = 0.0;
  // Factor by which a box's translation sigmas grow at this range.
  double observationNoiseGrowth(double range_m) const { return 1.0 + observation_sigma_growth_per_m * range_m; }
  // A box's position sigma along its length at this range.
  double boxLengthwiseSigma(double range_m) const { return observation_sigma[0] * observationNoiseGrowth(range_m); }
  // The sigmas of a box of this class (a moving object's or a landmark's): the configured ones,
  // with the class's heading sigma when that is larger.
  Vector6 boxSigma(const std::string& type, bool moving) const;
  // Odometry sigmas are multiplied by this when the odometry fell back to a prediction or
  // did not arrive (then the pose is predicted with constant velocity).
  double degraded_odometry_scale = 10.0;
  // Use the odometry message's covariance, its translation and rotation standard deviations
  // times odometry_covariance_scale's two factors (a Hessian's covariance is optimistic),
  // instead of odometry_sigma when it is valid.
  bool use_odometry_covariance = true;
  Eigen::Vector2d odometry_covariance_scale = Eigen::Vector2d(5.0, 5.0);  // translation, rotation
  // The odometry factor tested against the motion the landmarks and tracked objects imply, and
  // down-weighted where they disagree beyond both covariances (odometry_consistency.hpp).
  ConsistencyOptions odometry_check;

  // Per-object registration (object_registration.hpp): the classes whose own points, registered
  // from scan to scan, measure their pose changes (eq. 10's c) beside the boxes; empty: none, the
  // box chain alone, the default). Pedestrians belong outside it: a walker 20 m away has a few
  // dozen points on a body that changes shape as it walks.
  std::vector<std::string> registration_types;
  RegistrationOptions registration;
  // The points taken for an object (the node's selection): its box grown by a margin on every
  // side but the bottom, which is raised registration_ground_clearance above the box's floor (the
  // ground). The margin is this (m), or this many standard deviations of the box's position along
  // its length at its range (observation_sigma x observationNoiseGrowth) when that is more: the
  // faces a scan shows lie on the box's edges, and a far box's error (0.4 m at 100 m) put a
  // truck's front face outside a 0.2 m margin in every other scan.
  double registration_box_margin = 0.2;
  double registration_box_margin_sigmas = 2.0;
  // A moving vehicle the detector missed in a scan: its points there, cropped where its chain
  // predicts it, measured as a detection's (SlidingWindow::addMissedVehicles).
  bool registration_missed_vehicles = true;
  // A young vehicle without a registration: its speed along the line of sight from the face its
  // points show (line_of_sight.hpp), over the scan pairs with at least line_of_sight_min_points
  // in both scans (below 20, half the simulated pairs were more than 1 m/s off) among its last
  // line_of_sight_pairs frames, worth line_of_sight_sigma (m/s; the measured spread of the good
  // pairs, 0.24-0.39). line_of_sight_pairs 0: not used.
  int line_of_sight_min_points = 20;
  // The young path also takes pairs of this many points or more, each only where another pair
  // agrees with it (medianPairVelocity); the chain only those of line_of_sight_min_points.
  int line_of_sight_young_min_points = 10;
  double line_of_sight_max_angle_deg = 10.0;  // the box's heading from the line of sight (facesTheSensor)
  int line_of_sight_pairs = 3;
  double line_of_sight_sigma = 0.3;
  // A pair is judged by the face's last line_of_sight_series scans (this one included): it counts
  // where both its scans lie within line_of_sight_tolerance (m) of the robust line through them,
  // whatever its points, and never where one does not (faceSamplesOnLine; fewer than 4 of those
  // scans: judged by its points as above; 0: never judged).
  int line_of_sight_series = 6;
  double line_of_sight_tolerance = 0.15;
  // Each pair also a factor on a vehicle's chain once it spans the window, for the frames no
  // registration measured (sight_speed_factor.hpp).
  bool line_of_sight_chain = true;
  // A vehicle that shows its side: its speed along its heading from the side's ends (side_ends.hpp),
  // a young one's from the line through its window's side scans, its chain's from each scan pair
  // (as the line of sight's: line_of_sight_min_points, line_of_sight_chain). side_azimuth_step_deg
  // is the lidar's column spacing (0: not used); a scan counts only where its ends lie within
  // side_length_tolerance (m) of the vehicle's mean box length.
  double side_azimuth_step_deg = 0.0;
  double side_length_tolerance = 0.5;
  // A registering vehicle's heading from the faces its points show, each scan a factor on its
  // pose (face_heading.hpp).
  bool face_heading = true;
  // The scans' firing order, from the config's lidar section (LidarConfig): a registered object's
  // points are moved to the scan's reference instant (its pose's, its boxes') by the ego's motion
  // and the object's over the time from their firing. period 0: de-skewed scans.
  SweepTiming sweep;
  double registration_ground_clearance = 0.3;
  // Publish each registered vehicle's box made to cover its accumulated points (object_model.hpp,
  // refinedBox): its size where a side was seen end to end, its place from the faces it showed.
  bool registration_refine_boxes = true;

  // Robust loss on (landmark) observations, the factors that see outliers: none|huber|cauchy,
  // scale in whitened units (1 = one sigma).
  std::string observation_loss = "cauchy";
  double observation_loss_scale = 1.0;

  // A new object is dynamic when the least-squares speed of its positions in the window
  // exceeds static_max_speed (m/s) and dynamic_min_sigmas standard deviations of that speed
  // (which box noise alone would cause); else it starts as a static landmark.
  double static_max_speed = 1.0;
  // A dynamic object's reported velocity: its optimized chain's displacement over the last this
  // many frames. With the constant-acceleration factor the newest pose change (1) is the best
  // estimate; a longer chord lags behind a braking car by half its span.
  int velocity_frames = 1;
  // A pedestrian's (any non-vehicle's) velocity: the line through its boxes of the last this many
  // seconds, the window's and those that left it; the window's alone when shorter.
  double walker_line_span_s = 0.0;
  // The RMS speed of walking pedestrians (m/s): a walker's line is fused with a zero-mean prior of
  // this spread (withSpeedPrior). 0: none.
  double walker_rms_speed = 0.0;
  // A still object is judged again at every frame, a pedestrian by its line, a vehicle by what its
  // points measured over the last frames: dynamic when faster than static_max_speed and this many
  // standard deviations of that velocity (0: never).
  double switch_min_sigmas = 0.0;
  double dynamic_min_sigmas = 2.0;
  // A landmark turns dynamic when its last `switch_frames` observations each lie farther than
  // `switch_distance` (m, bird's-eye) from it (a parked car pulls out).
  double switch_distance = 0.6;
  int switch_frames = 2;

  // Levenberg-Marquardt (WindowSolver) steps per frame and stopping tolerances.
  int max_iterations = 2;
  double function_tolerance = 1e-6;
  double gradient_tolerance = 1e-10;
  double parameter_tolerance = 1e-8;
  // Marginal covariances of the newest ego pose and the tracks (WindowSolver::covariance).
  bool compute_covariance = true;
  // Threads for the objects' eliminations and the factors' linearizations (the caller's
  // included); the estimate is the same for any number.
  int solver_threads = 2;

  // Reads every key above from `section` (not finish(): the node reads its own keys too).
  static BackendConfig read(ConfigSection& section);
};

// diag(1 / sigma): the square-root information of independent residual components.
Matrix6 sqrtInformation(const Vector6& sigma);

}  // namespace dlslot::backend
