// Scan-to-scan odometry (A-LOAM laserOdometry, LOAM section V-B): the sharp and flat points of
// the current scan are matched to edge lines and planes of the previous scan's less-sharp and
// less-flat points, and T_prev_cur is solved from the constant-velocity guess.
#pragma once

#include "feature_extraction.hpp"
#include "point_grid.hpp"
#include "pose_solver.hpp"

namespace dlslot::odometry {

// The previous scan's features with nearest-neighbour grids over them. Edge points are sparse
// (coarse cells keep the number of empty cells visited small), plane points dense. The grids
// are built on the first index() after reset(): when the map registration alone handles a scan
// (ScanToScanConfig::every_scan false) most scans never need them.
class ScanReference {
 public:
  void reset(ScanFeatures features);  // keeps the less-sharp and less-flat points
  void index();                       // builds the grids unless built since reset()
  bool indexed() const { return indexed_; }
  bool empty() const { return edges_.empty() && planes_.empty(); }
  const FeatureCloud& edges() const { return edges_; }
  const FeatureCloud& planes() const { return planes_; }
  const PointGrid& edgeGrid() const { return edge_grid_; }
  const PointGrid& planeGrid() const { return plane_grid_; }

 private:
  FeatureCloud edges_, planes_;
  bool indexed_ = false;
  PointGrid edge_grid_{3.0}, plane_grid_{1.0};  // fastest of 0.25-3 m on the real slice
};

// Correspondences of the current scan's sharp/flat points at T_prev_cur (`previous` indexed).
Matches matchScanToScan(const ScanFeatures& current, const ScanReference& previous, const Pose& T_prev_cur,
                        const ScanToScanConfig& cfg);

// Both registrations index `previous` first.
Registration registerScanToScan(const ScanFeatures& current, ScanReference& previous, const Pose& guess,
                                const ScanToScanConfig& cfg);

// The second scan of a sequence has no motion to extrapolate, yet the vehicle may already move
// fast (a sequence starting on a highway): registration starts from each forward distance of
// cfg.first_motion_guesses_m and keeps the solution with the most inlier correspondences.
Registration registerFirstMotion(const ScanFeatures& current, ScanReference& previous, const ScanToScanConfig& cfg);

}  // namespace dlslot::odometry
