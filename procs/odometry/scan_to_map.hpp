// Scan-to-map refinement (A-LOAM laserMapping, LOAM section VI): the scan's voxel-thinned edge
// and plane points are matched to lines and planes fitted to their nearest local-map points,
// and T_world_lidar is solved from the scan-to-scan prediction.
#pragma once

#include "local_map.hpp"
#include "pose_solver.hpp"

namespace dlslot::odometry {

// Correspondences of the scan's edge/plane points (lidar frame) at T_world_lidar.
Matches matchScanToMap(const FeatureCloud& edges, const FeatureCloud& planes, const LocalMap& map,
                       const Pose& T_world_lidar, const ScanToMapConfig& cfg);

Registration registerScanToMap(const FeatureCloud& edges, const FeatureCloud& planes, const LocalMap& map,
                                  const Pose& guess, const ScanToMapConfig& cfg);

}  // namespace dlslot::odometry
