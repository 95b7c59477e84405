// One object's motion between two scans from its own points (not in the paper; it measures the
// pose-change vertex c of eq. 10 directly): the object's points of the previous scan registered
// to its points of the current scan, both in the world frame, from a predicted motion.
//
// Point-to-plane Gauss-Newton with Cauchy weights, centred on the object. Each scan's points are
// prepared once (prepareObject), in the frame they arrive: thinned to one point per half voxel,
// binned in a small dense voxel grid (for the next frame's nearest-point searches, as the
// target), and a subsample of them given the plane of their nearest neighbours (for the next
// frame, as the source). A track's current scan is the next frame's previous one, so the
// thinning and the plane fits are done once per scan, not once per registration: the planes are
// the source's (the previous scan's), a previous point's nearest current point is searched in
// its voxel's 3x3x3 neighbourhood. Why not PCL's VoxelGrid, kd-tree and normal estimation (or
// GICP): on these clouds of a few hundred points they cost several times as much
// (bench/object_registration_bench.cpp), and 20 objects must fit in 3 ms a frame. The voxel grows
// with range, so a far object's neighbourhood spans several scan rings (a single ring is a line,
// not a plane).
//
// The motion is measured in the ground plane (x, y, yaw; world z up): a car's faces are nearly
// all vertical and its roof is seen at a grazing angle, so its height, roll and pitch were weakly
// and unfaithfully measured (from an exact start the full 6-DoF fit drifted 0.1-0.7 m in height,
// and a measurement that says so with confidence pulls the chain); they keep the prediction's
// values and get no information.
//
// The result's information is the Gauss-Newton Hessian over the residuals' own variance (its
// whitened, robust-weighted spread, floored by the sensor's noise), shrunk by
// information_scale: neighbouring points on one surface are not independent. Directions the
// points do not constrain (a flat side seen edge-on: no motion along it) are removed from the
// information rather than guessed, so the measurement says nothing there.
#pragma once

#include <Eigen/Core>
#include <memory>
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
  int plane_neighbours = 8;       // a source point's plane: its nearest this many points ...
  int min_plane_points = 5;       // ... at least this many within a voxel's reach
  double max_planarity = 0.3;     // smallest / middle eigenvalue of those points: above, not a plane
  double cauchy_scale = 0.05;     // m: residuals beyond this are down-weighted (neighbours, ground)
  // The motion in the ground plane only (x, y, yaw; above); false: all 6 directions.
  bool planar = true;
  double max_residual = 0.3;      // m: correspondences beyond are not used
  // A start half a metre off needs 5 steps of max_step before the fine convergence.
  int max_iterations = 15;
  double max_step = 0.1;          // m (and rad x 2 m): the largest step of one iteration
  double converged_step = 1e-3;   // m (and rad x 1 m): the step that ends the iterations
  double point_sigma = 0.02;      // m: floor of the residuals' standard deviation (sensor noise)
  double information_scale = 0.1; // neighbouring points are correlated: the information times this
  // What one registration is worth at best, whatever its point count: every scan's rings cross the
  // object at other heights, so its error does not shrink as 1/sqrt(points) (simulated drives,
  // fully measured cars with the true ego: 1.7 cm a frame, docs/object-motion.md). Added to the
  // measured directions' variance; without it a registration of a near car claims millimetres, and
  // under the graph's Cauchy loss a chain a few centimetres off then ignores it altogether.
  double accuracy_m = 0.02;
  double accuracy_rad = 0.0052359877559829887;  // 0.3 deg
  // A horizontal direction whose marginal standard deviation exceeds this (m) is not measured.
  double max_sigma = 0.03;
  double min_inlier_fraction = 0.5;  // fewer previous points with a plane within max_residual: kPoorFit
  double max_correction = 1.0;       // m: a result this far from the prediction is kDiverged
  // The accumulated model (object_model.hpp): the object's points of up to this many consecutive
  // scans, moved along by their registrations (1: the previous scan alone), at most
  // max_model_points after thinning to one point per half voxel, newest first.
  int model_frames = 5;
  int max_model_points = 1200;
};

// The information of a registration (any tangent with translation first) with the accuracy floor
// of `o` added to each measured direction's variance.
Matrix6 withAccuracyFloor(const Matrix6& information, const RegistrationOptions& o);

enum class RegistrationOutcome {
  kMeasured,      // every direction measured (x, y and yaw when planar)
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

// The indices of `points` kept when thinned to one point per cell of edge `cell` (the first one
// met in each cell), then every k-th of those if more than `max_points` remain.
std::vector<int> thinIndices(const ObjectPoints& points, double cell, int max_points);

// One scan's points of an object, prepared for registration (world frame): as the target of
// this frame's registration and as the source of the next frame's.
class PreparedObject {
 public:
  struct Plane {
    bool valid = false;
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  };

  // `points`: the object's points of one scan (or its model), world frame; `range`: its distance
  // from the sensor (m), which sets the voxel size. `with_planes` false: a target only (no source
  // subsample, no plane fits), when the source is the object's model.
  PreparedObject(const ObjectPoints& points, double range, const RegistrationOptions& options, bool with_planes = true);

  int rawPoints() const { return raw_points_; }
  double voxel() const { return voxel_; }
  // Thinned to one point per half voxel, at most max_target_points.
  const std::vector<Eigen::Vector3d>& points() const { return points_; }
  const Eigen::Vector3d& centroid() const { return centroid_; }
  // At most max_source_points of them, each with the plane of its nearest neighbours (invalid:
  // none, or not flat).
  const std::vector<Eigen::Vector3d>& sourcePoints() const { return source_; }
  const std::vector<Plane>& sourcePlanes() const { return planes_; }
  // The index of the point nearest to q within one voxel's reach (-1: none), and its squared distance.
  int nearest(const Eigen::Vector3d& q, double* d2) const;

 private:
  bool cellOf(const Eigen::Vector3d& p, int* c) const;
  Plane fit(const Eigen::Vector3d& p, const RegistrationOptions& options) const;

  int raw_points_ = 0;
  double voxel_ = 0;
  std::vector<Eigen::Vector3d> points_;
  Eigen::Vector3d centroid_ = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> source_;
  std::vector<Plane> planes_;
  // The points binned in a dense voxel grid: point indices per voxel (CSR).
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();
  int dims_[3] = {0, 0, 0};
  std::vector<int> start_, members_;
};

// `previous` and `current`: the object's prepared points of the two scans. `prediction`: the
// predicted M.
RegistrationResult registerObject(const PreparedObject& previous, const PreparedObject& current, const Pose& prediction,
                                  const RegistrationOptions& options);
// The same motion M (previous -> current) measured against the object's accumulated model of the
// previous scans (object_model.hpp, world frame of the previous scan): the current scan's points
// (the source, with their planes) registered to the model's (the target, `model` prepared
// without planes), and the result turned round. This way round every current point has the
// model's points around it (the model holds the previous scan and more), where the model's points
// as the source would look for counterparts of faces and ring heights the current scan does not
// have and count them as a poor fit.
RegistrationResult registerToModel(const PreparedObject& model, const PreparedObject& current, const Pose& prediction,
                                   const RegistrationOptions& options);
// M^-1 with its information: in the tangent at M^-1 (as for M: t + dt, Exp(dtheta) R).
RegistrationResult inverted(const RegistrationResult& r);
// The same from the raw points (both prepared here, at the same range).
RegistrationResult registerObject(const ObjectPoints& previous, const ObjectPoints& current, const Pose& prediction,
                                  double range, const RegistrationOptions& options);

}  // namespace dlslot::backend
