// One object's motion between two scans from its own points (not in the paper; it measures the
// pose-change vertex c of eq. 10 directly): the object's points of the previous scan registered
// to its points of the current scan, both in the world frame, from a predicted motion.
//
// Point-to-plane Gauss-Newton with Cauchy weights, centred on the object. The current points are
// binned in a small dense voxel grid around the object: a previous point's nearest current point
// is searched in its voxel's 3x3x3 neighbourhood, and that point's plane (its nearest neighbours
// there) is fitted once and cached. Why not PCL's kd-tree (or GICP): k-nearest-neighbour normals
// and a query per point and iteration cost about 1 ms a car, and 20 objects must fit in 3 ms a
// frame (bench/object_registration_bench.cpp). The voxel grows with range, so a far object's
// neighbourhood spans several scan rings (a single ring is a line, not a plane).
//
// The result's information is the Gauss-Newton Hessian over the residuals' own variance (its
// whitened, robust-weighted spread, floored by the sensor's noise), shrunk by
// information_scale: neighbouring points on one surface are not independent. Directions the
// points do not constrain (a flat side seen edge-on: no motion along it) are removed from the
// information rather than guessed, so the measurement says nothing there.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "backend/se3.hpp"

namespace dlslot::backend {

struct RegistrationOptions {
  int min_points = 30;            // fewer points in either scan: no measurement (kTooFewPoints)
  int max_source_points = 80;     // the previous scan's points beyond this are thinned (time bound)
  int max_target_points = 300;    // and the current scan's
  // Voxel edge (m) of the current points' grid: at least min_voxel, and voxel_per_m x the range so
  // that a neighbourhood of 3 voxels spans 2-3 scan rings of a 64-beam lidar (0.4 deg apart).
  double min_voxel = 0.25;
  double voxel_per_m = 0.012;
  int plane_neighbours = 8;       // a current point's plane: its nearest this many points ...
  int min_plane_points = 5;       // ... at least this many within a voxel's reach
  double max_planarity = 0.3;     // smallest / middle eigenvalue of those points: above, not a plane
  double cauchy_scale = 0.05;     // m: residuals beyond this are down-weighted (neighbours, ground)
  double max_residual = 0.3;      // m: correspondences beyond are not used
  int max_iterations = 10;
  double max_step = 0.1;          // m (and rad x 2 m): the largest step of one iteration
  double converged_step = 1e-3;   // m (and rad x 1 m): the step that ends the iterations
  double point_sigma = 0.02;      // m: floor of the residuals' standard deviation (sensor noise)
  double information_scale = 0.1; // neighbouring points are correlated: the information times this
  // A horizontal direction whose marginal standard deviation exceeds this (m) is not measured.
  double max_sigma = 0.03;
  double min_inlier_fraction = 0.5;  // fewer previous points with a plane within max_residual: kPoorFit
  double max_correction = 1.0;       // m: a result this far from the prediction is kDiverged
};

enum class RegistrationOutcome {
  kMeasured,      // every direction measured
  kPartial,       // one horizontal translation direction unmeasured (e.g. a flat side edge-on)
  kTooFewPoints,
  kDegenerate,    // neither horizontal direction measured
  kPoorFit,       // too few of the previous points found a plane of the current scan
  kDiverged,      // the result left the prediction by more than max_correction
};
const char* toString(RegistrationOutcome outcome);
constexpr int kNumRegistrationOutcomes = 6;

struct RegistrationResult {
  RegistrationOutcome outcome = RegistrationOutcome::kTooFewPoints;
  // M: previous points -> current points, world frame (o_t = M o_{t-1} for a rigid object).
  Pose motion = Pose::Identity();
  // Information of M in the PoseManifold's tangent at M (t + dt, Exp(dtheta) R), world frame;
  // rank-deficient when a direction was not measured.
  Matrix6 information = Matrix6::Zero();
  int source_points = 0, target_points = 0, inliers = 0, iterations = 0;
  double rms_residual = 0;  // m, point-to-plane, of the inliers at the result

  bool ok() const { return outcome == RegistrationOutcome::kMeasured || outcome == RegistrationOutcome::kPartial; }
};

using ObjectPoints = std::vector<Eigen::Vector3f>;

// `previous` and `current`: the object's points of the two scans, world frame. `prediction`: the
// predicted M. `range`: the object's distance from the sensor (m), which sets the voxel size.
RegistrationResult registerObject(const ObjectPoints& previous, const ObjectPoints& current, const Pose& prediction,
                                  double range, const RegistrationOptions& options);

}  // namespace dlslot::backend
