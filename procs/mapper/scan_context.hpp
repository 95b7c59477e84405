// Scan Context (Kim and Kim, "Scan Context: Egocentric Spatial Descriptor for Place Recognition
// within 3D Point Cloud Map", IROS 2018): the scan seen from above, split into rings (range) x
// sectors (azimuth), each cell holding the highest point's height. A place seen again from a
// different heading gives the same matrix with its columns shifted, so the distance is the best
// column shift's mean cosine distance, and that shift gives the relative yaw.
#pragma once

#include <Eigen/Core>

#include "dlslot/types.hpp"

namespace dlslot::mapper {

struct ScanContextParams {
  int rings = 20, sectors = 60;
  double max_radius_m = 50.0;
  double height_offset_m = 2.0;  // added to z so that the road (about -1.7 m in the lidar frame) is > 0
};

struct ScanContext {
  Eigen::MatrixXf cells;  // rings x sectors; 0 where no point fell
};

// points: lidar frame (x y z intensity columns).
ScanContext makeScanContext(const PointCloud& points, const ScanContextParams& params);

struct ScanContextMatch {
  double distance = 1.0;  // 0 (identical) .. 1 (orthogonal or no common columns)
  int shift = 0;          // sectors: column j of `a` matches column j + shift of `b`
  double yaw = 0.0;       // radians: Rz(yaw) maps a's frame to b's (p_b = Rz(yaw) p_a, about the sensor)
};

// The distance of two descriptors at their best column shift.
ScanContextMatch compare(const ScanContext& a, const ScanContext& b);

}  // namespace dlslot::mapper
