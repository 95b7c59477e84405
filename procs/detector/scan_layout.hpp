// Where each point of a scan lies in the two grids the detector works on: the polar ground grid
// (azimuth sector x range bin) and the range image (azimuth column x elevation row). Computed
// once per scan; points outside the scan window or not finite get cell -1 and are ignored.
#pragma once

#include <cstdint>
#include <vector>

#include "detector/detector_config.hpp"
#include "dlslot/types.hpp"

namespace dlslot::detector {

struct ScanLayout {
  int sectors = 0, bins = 0, columns = 0, rows = 0;
  double bin_m = 1.0;
  float row_tan_min = 0.0f, row_step = 0.004f;
  // Per point (index into the scan): polar ground cell sector * bins + bin, -1 when the point is
  // not used (NaN, too near, too far); its range-image column and row; its horizontal range.
  std::vector<int32_t> cell;
  std::vector<int16_t> column, row;
  std::vector<float> range;
  int num_used = 0;
};

// The layout of `scan` for the window, ground grid and range image of `cfg`.
ScanLayout layoutScan(const PointCloud& scan, const DetectorConfig& cfg);

// atan2(y, x) in [-pi, pi] within 1e-5 rad, without the library call (a few ns a point).
float fastAtan2(float y, float x);

}  // namespace dlslot::detector
