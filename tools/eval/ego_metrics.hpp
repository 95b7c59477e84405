// Ego-motion accuracy against ground truth (design brief section 5): ATE after SE(3) Umeyama
// alignment, RPE over a fixed number of frames, and the KITTI odometry devkit's segment errors.
#pragma once

#include <optional>
#include <vector>

#include "trajectory.hpp"

namespace dlslot::eval {

// The rigid transform (no scale) that best maps the estimated positions onto the ground-truth
// ones in the least-squares sense (Umeyama 1991). Needs equally many points, at least one.
Pose alignUmeyama(const std::vector<Eigen::Vector3d>& estimated, const std::vector<Eigen::Vector3d>& truth);

// Every function below needs `est` and `gt` over the same frames (commonFrames) and throws
// std::invalid_argument otherwise.

// RMSE of the position error, after Umeyama alignment or as given (both start in the lidar frame
// of the first scan, so the unaligned number is meaningful too).
double ateRmse(const Trajectory& est, const Trajectory& gt, bool align);
// Per-frame position error after alignment (for the error-over-distance plot).
std::vector<double> alignedPositionErrors(const Trajectory& est, const Trajectory& gt);
// Distance travelled along the ground truth up to each frame.
std::vector<double> pathDistances(const Trajectory& gt);

// Relative pose error over pairs of frames `delta` scan indices apart:
// E = inv(inv(G_i) G_j) * inv(P_i) P_j; RMSE of |t(E)| (m) and of angle(R(E)) (deg).
// velocity_rmse_mps: the same translation errors over the pairs' time spans (when the trajectory
// has stamps): the ego's velocity error over `delta` scans, which every object velocity over
// ground inherits.
struct Rpe {
  double t_rmse_m = 0, r_rmse_deg = 0;
  int pairs = 0;
  std::optional<double> velocity_rmse_mps;
};
std::optional<Rpe> relativePoseError(const Trajectory& est, const Trajectory& gt, int delta);

// The KITTI devkit's calcSequenceErrors: from every 10th frame, for each segment length L, the
// first frame more than L metres further along the ground truth; error of the relative pose over
// the segment divided by L, averaged over all segments.
struct SegmentErrors {
  double t_rel_pct = 0;           // mean translation error / length, in %
  double r_rel_deg_per_100m = 0;  // mean rotation error / length, in deg per 100 m
  int segments = 0;
  std::vector<double> lengths;            // the lengths that had at least one segment
  std::vector<double> t_rel_pct_by_length;
};
std::optional<SegmentErrors> segmentErrors(const Trajectory& est, const Trajectory& gt,
                                           const std::vector<double>& lengths_m, int step_frames = 10);
extern const std::vector<double> kDevkitLengths;  // 100, 200, ..., 800 m
extern const std::vector<double> kShortLengths;   // 10, 20, ..., 80 m

struct EgoMetrics {
  int frames = 0;
  double path_length_m = 0;
  std::optional<double> ate_rmse_m, ate_unaligned_rmse_m;
  std::optional<double> rpe1_t_m, rpe1_r_deg, rpe10_t_m, rpe10_r_deg;
  std::optional<double> velocity_rmse_mps;  // over 5 scans, as the backend's object velocities
  std::optional<double> t_rel_pct, r_rel_deg_per_100m, t_rel_short_pct, r_rel_short_deg_per_100m;
  std::optional<SegmentErrors> devkit, short_segments;
  // Scans where the estimate's own speed changed faster than any car can (implausibleSpeedJumps):
  // a run whose ego is lost says so, with or without ground truth.
  std::optional<double> implausible_frames;
};
// Scans whose estimated speed (each scan's motion over its time step) differs from the previous
// scan's by more than 2 g times the step: twice the braking of a car on dry road, so neither a
// real manoeuvre nor the per-scan noise of a registration (a few cm) reaches it, while a
// velocity that was wrong and is re-anchored (metres per scan) does. nullopt without stamps.
std::optional<double> implausibleSpeedJumps(const Trajectory& est);
EgoMetrics evaluateEgo(const Trajectory& est, const Trajectory& gt);

// The backend's test of each frame's odometry factor against its landmarks and tracked objects
// (SLOT_STATE odometry_check): frames tested, those where they disagreed beyond both
// covariances, of them those down-weighted, and the largest disagreement.
struct OdometryChecks {
  int tested = 0, disagreed = 0, downweighted = 0;
  double max_disagreement_m = 0;
  std::vector<int> disagreed_frames;
};

}  // namespace dlslot::eval
