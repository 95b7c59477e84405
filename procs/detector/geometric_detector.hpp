// The whole geometric detector on one scan: scan layout, per-sector ground, range-image clusters,
// an L-shape rectangle per cluster, class, completed box and score. No state between scans.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "detector/detector_config.hpp"
#include "detector/object_class.hpp"
#include "dlslot/convert.hpp"
#include "dlslot/types.hpp"

namespace dlslot::detector {

struct DetectionResult {
  std::vector<Box> boxes;  // lidar frame; kUnknownType boxes included
  std::vector<ClusterShape> shapes;  // what was measured of each box's cluster (same order)
  int points_used = 0, obstacle_points = 0, clusters = 0;
  std::map<std::string, int> per_type;  // boxes per type
  StageTimings timings;                 // layout, ground, clustering, boxes (ms)
};

// Detects the objects of one scan (lidar frame). Points that are not finite are skipped; an empty
// scan gives no boxes.
DetectionResult detectObjects(const PointCloud& scan, const DetectorConfig& cfg);

}  // namespace dlslot::detector
