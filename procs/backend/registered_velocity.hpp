// A young vehicle's velocity over ground from its own points. Until its chain spans the window
// a vehicle's velocity is the line through its few boxes (motion_evidence.hpp), each box good to
// 0.1-0.3 m: over 2-4 frames that line is worth 0.5-2 m/s. One registration of its points
// between consecutive scans (object_registration.hpp) measures the same motion to a few
// centimetres in the directions it constrains; in the world frame it carries the ego's
// per-frame error too. Both are fused by information, bird's-eye.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "backend/se3.hpp"

namespace dlslot::backend {

// A velocity estimate (m/s, world x-y) with its information (rank-deficient where unmeasured).
struct VelocityEvidence {
  Eigen::Vector2d velocity = Eigen::Vector2d::Zero();
  Eigen::Matrix2d information = Eigen::Matrix2d::Zero();
};

// The velocity a registration implies: M (world, o_t = M o_{t-1}) moves the object's centre
// p_prev (world, at t-1) by M p_prev - p_prev in dt seconds. Its information: the registration's
// (`information`, world tangent of M: translation then rotation) carried to the centre's
// displacement with the rotation marginalized, then the ego's per-frame translation error
// (ego_sigma_m per axis, it moves both scans' points against each other) added to each measured
// direction. As a measurement of the velocity some time later, the velocity's possible change
// since (change_sigma_mps per axis: a vehicle accelerating at its RMS acceleration over that
// time) adds to each measured direction's variance too. Nothing when dt <= 0 or no horizontal
// direction was measured.
std::optional<VelocityEvidence> registeredVelocity(const Pose& M, const Matrix6& information,
                                                   const Eigen::Vector3d& p_prev, double dt, double ego_sigma_m,
                                                   double change_sigma_mps = 0.0);

// The information-weighted mean of a line's velocity (covariance line_covariance, full rank) and
// registered velocities. A registration whose velocity disagrees with the line beyond the
// chi-square gate (99 % for its measured directions) is another object's or a failed one and
// is left out. Returns the fused velocity, its covariance and how many registrations it used.
struct FusedVelocity {
  Eigen::Vector2d velocity = Eigen::Vector2d::Zero();
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Identity();
  int used = 0;
};
FusedVelocity fuseVelocities(const Eigen::Vector2d& line_velocity, const Eigen::Matrix2d& line_covariance,
                             const std::vector<VelocityEvidence>& registered);

// Evidence that an object moves from velocities alone: along some direction they measured, the
// information-weighted mean speed exceeds min_speed and min_sigmas of its standard deviation. A
// still vehicle seen end-on measures its motion along the line of sight only; its other direction
// is noise and counts for nothing.
bool measuredMotion(const std::vector<VelocityEvidence>& evidence, double min_speed, double min_sigmas);

}  // namespace dlslot::backend
