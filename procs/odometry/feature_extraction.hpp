// LOAM feature extraction (A-LOAM scanRegistration, LOAM section V-A): points are grouped by
// beam, each ring is cut into sectors, and in every sector the highest-curvature points become
// edge features and the lowest plane features, never two next to each other.
#pragma once

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include "dlslot/types.hpp"
#include "odometry_config.hpp"

namespace dlslot::odometry {

// Feature points in the lidar frame; intensity holds the beam index, and points are ordered by
// beam (scan-to-scan matching walks neighbouring beams through this order).
using FeatureCloud = pcl::PointCloud<pcl::PointXYZI>;

struct ScanFeatures {
  FeatureCloud sharp;       // strongest edges: matched against the previous scan
  FeatureCloud less_sharp;  // all edges: the next scan matches against these, and the map
  FeatureCloud flat;        // flattest points: matched against the previous scan
  FeatureCloud less_flat;   // every non-edge point, thinned along the ring
  int num_points = 0;       // points that passed the range and beam checks
};

// `removed` (when given, one flag per scan point): points left out, as if not in the scan (the
// detected objects of A-LOAM*, without copying the rest of the scan).
ScanFeatures extractFeatures(const PointCloud& scan, const FeatureConfig& cfg,
                             const std::vector<bool>* removed = nullptr);

}  // namespace dlslot::odometry
