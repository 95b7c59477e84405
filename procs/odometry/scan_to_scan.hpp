// Scan-to-scan odometry (A-LOAM laserOdometry, LOAM section V-B): the sharp and flat points of
// the current scan are matched to edge lines and planes of the previous scan's less-sharp and
// less-flat points, and T_prev_cur is solved from the constant-velocity guess.
#pragma once

#include <pcl/kdtree/kdtree_flann.h>

#include "feature_extraction.hpp"
#include "pose_solver.hpp"

namespace dlslot::odometry {

// The previous scan's features with kd-trees over them.
class ScanReference {
 public:
  void reset(const ScanFeatures& features);
  bool empty() const { return edges_->empty() && planes_->empty(); }
  const FeatureCloud& edges() const { return *edges_; }
  const FeatureCloud& planes() const { return *planes_; }
  const pcl::KdTreeFLANN<pcl::PointXYZI>& edgeTree() const { return edge_tree_; }
  const pcl::KdTreeFLANN<pcl::PointXYZI>& planeTree() const { return plane_tree_; }

 private:
  FeatureCloud::Ptr edges_{new FeatureCloud}, planes_{new FeatureCloud};
  pcl::KdTreeFLANN<pcl::PointXYZI> edge_tree_, plane_tree_;
};

// Correspondences of the current scan's sharp/flat points at T_prev_cur.
Matches matchScanToScan(const ScanFeatures& current, const ScanReference& previous, const Pose& T_prev_cur,
                        const ScanToScanConfig& cfg);

Registration registerScanToScan(const ScanFeatures& current, const ScanReference& previous,
                                    const Pose& guess, const ScanToScanConfig& cfg);

// The second scan of a sequence has no motion to extrapolate, yet the vehicle may already move
// fast (a sequence starting on a highway): registration starts from each forward distance of
// cfg.first_motion_guesses_m and keeps the solution with the most inlier correspondences.
Registration registerFirstMotion(const ScanFeatures& current, const ScanReference& previous,
                                 const ScanToScanConfig& cfg);

}  // namespace dlslot::odometry
