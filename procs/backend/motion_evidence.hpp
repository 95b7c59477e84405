// The window's evidence for the static/dynamic decision (paper III-D: "we first use the
// object's trajectory in the sliding window to preliminarily judge the dynamic or static
// state"), and for a landmark that starts to move.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <optional>
#include <vector>

namespace dlslot::backend {

struct TimedPosition {
  double t = 0;  // seconds
  Eigen::Vector3d p = Eigen::Vector3d::Zero();  // world frame
};

struct SpeedFit {
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  // m/s, world frame
  double speed = 0;  // m/s, bird's-eye
  double sigma = 0;  // its standard deviation per axis for positions with noise position_sigma
};

// The least-squares line through the positions; nothing when they span less than two
// distinct times. A static object's fitted speed is noise of about `sigma` per axis, so a speed
// of a few sigmas is evidence of motion.
std::optional<SpeedFit> fitSpeed(const std::vector<TimedPosition>& positions, double position_sigma);
// The same line with the boxes the tracker gave the wrong track left out: the consensus of the
// pairs of positions (more than 3 positions; else fitSpeed). With a vehicle's unit bird's-eye
// `heading`, a pair that moved across it by more than the inlier gate is not a candidate (a
// vehicle does not move sideways: the two boxes are two objects), which also lets 3 positions
// outvote one.
std::optional<SpeedFit> fitSpeedAmongOutliers(const std::vector<TimedPosition>& positions, double position_sigma,
                                              double inlier_sigmas, const Eigen::Vector2d* heading = nullptr);

// A wheeled vehicle moves along its heading. The fit's velocity component across the unit
// bird's-eye `heading` is that of positions alone (standard deviation fit.sigma); the heading
// says it is zero, to within the speed times `heading_sigma` (rad). Returns the fit's velocity
// with that component replaced by the variance-weighted mean of the two.
Eigen::Vector3d velocityAlongHeading(const SpeedFit& fit, const Eigen::Vector2d& heading, double heading_sigma);

// A bird's-eye velocity with its covariance.
struct PlanarVelocity {
  Eigen::Vector2d velocity = Eigen::Vector2d::Zero();
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Identity();
};

// The linear minimum-mean-square-error velocity of an object of a kind that moves in no preferred
// direction at `rms_speed` (the RMS speed of its moving members; a linear estimator needs no more
// than the second moments): the measured `velocity` (full-rank `covariance`) fused by information
// with a zero-mean prior of rms_speed^2 / 2 per axis. A walker's line through its first two or
// three boxes (1-2 m/s uncertain) is drawn toward standing as far as it is uncertain; a line over
// seconds (0.1-0.2 m/s) hardly moves. rms_speed <= 0: unchanged.
PlanarVelocity withSpeedPrior(const Eigen::Vector2d& velocity, const Eigen::Matrix2d& covariance, double rms_speed);

// Evidence of motion: a speed above `min_speed` and above `min_sigmas` standard deviations of it
// (box noise alone makes a still object's fitted speed a sigma or so).
inline bool movesBeyond(double speed, double sigma, double min_speed, double min_sigmas) {
  return speed > min_speed && speed > min_sigmas * sigma;
}

// The same for a bird's-eye velocity with its covariance: its speed against its standard deviation
// along it.
inline bool movesBeyond(const Eigen::Vector2d& velocity, const Eigen::Matrix2d& covariance, double min_speed,
                        double min_sigmas) {
  const double speed = velocity.norm();
  return speed > 0 &&
         movesBeyond(speed, std::sqrt(velocity.dot(covariance * velocity)) / speed, min_speed, min_sigmas);
}

// The same evidence on one axis. A still object's fitted velocity is noise of sigma per axis: its
// speed in the plane exceeds k sigmas with probability exp(-k^2 / 2) (Rayleigh), one component
// exceeds k1 sigmas with probability erfc(k1 / sqrt 2). Returns the k1 of the same probability
// (k = 2: 13.5 %, k1 = 1.49). A vehicle moves along its heading, so only the fit's component along
// it is evidence of motion; tested there, a still car is called moving no more often than in the
// plane, and a moving one is seen sooner.
double sigmasOnOneAxis(double plane_sigmas);

// True when the last `n` positions all lie farther than `distance` (bird's-eye) from `landmark`
// (false when there are fewer than n).
bool leftLandmark(const std::vector<Eigen::Vector3d>& positions, const Eigen::Vector3d& landmark, double distance,
                  int n);

}  // namespace dlslot::backend
