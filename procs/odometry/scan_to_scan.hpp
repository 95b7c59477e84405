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

// A motion no velocity can be trusted for: registration starts from `guess` and from each of the
// `forward` distances along the lidar's x axis (with `guess`'s rotation), and the solution with
// the most inlier correspondences wins. `hypotheses`, when given, is set to the number of starts
// registered.
Registration registerMotionHypotheses(const ScanFeatures& current, ScanReference& previous, const Pose& guess,
                                      const std::vector<double>& forward, const ScanToScanConfig& cfg,
                                      int* hypotheses = nullptr);
// A second motion hypothesis from the correspondences a registration rejected. At T_ref_cur each
// outlier (|residual| above huber_delta) whose residual a shift along the unit direction v (the
// reference frame) can explain votes for that shift; votes are binned `spacing` wide. When the
// most voted bin holds at least min_votes (scan-to-scan's min_correspondences: enough for a
// registration of its own), structure that the solution left unexplained moves together by that
// shift (posts of a corridor the wrong velocity put 2 m off, while traffic moving with the ego
// held the solution): returns the mean shift of the bin's votes, else NaN. Shifts within one bin of
// none are not counted: the residuals' own tails, and within the registration's reach anyway.
double outlierShift(const Matches& matches, const Pose& T_ref_cur, const Eigen::Vector3d& v, double huber_delta,
                    double spacing, double max_abs_shift, int min_votes);
// The forward distances 0, spacing, 2 spacing, ... max_forward_m (the search of the second scan
// and of a suspect velocity).
std::vector<double> forwardHypotheses(const ScanToScanConfig& cfg);
// The second scan of a sequence has no motion to extrapolate, yet the vehicle may already move
// fast (a sequence starting on a highway): it is searched as a velocity found suspect is, from
// starts one registration's reach apart (forwardHypotheses). Starts 1 m apart missed on 2 of 30
// simulated highway drives (seeds 13 and 16, 2.4 m a scan): a solution 0.7-0.8 m short, settled
// from a start beyond its reach, had the most inliers, and the speed took 4 scans to come back.
inline Registration registerFirstMotion(const ScanFeatures& current, ScanReference& previous,
                                        const ScanToScanConfig& cfg) {
  return registerMotionHypotheses(current, previous, Pose::Identity(), forwardHypotheses(cfg), cfg);
}

}  // namespace dlslot::odometry
