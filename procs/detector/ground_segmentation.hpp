// Ground removal that holds on slopes and kerbs: the ground is fitted per azimuth sector as a
// line walking outwards over range bins (after Himmelsbach et al., "Fast segmentation of 3D point
// clouds for ground vehicles", IV 2010), not as one plane for the whole scan. A bin's lowest point
// continues the ground when it lies within max_step_m + max_slope x run of the ground behind it
// (a kerb is a step, a hill a slope; the run counted up to 4 m, so the line does not climb onto
// what stands in a parked car's shadow); a bin whose lowest point is higher (a car's body, a wall)
// gets the ground continued from behind it along the sector's slope.
#pragma once

#include <cstdint>
#include <vector>

#include "detector/detector_config.hpp"
#include "detector/scan_layout.hpp"

namespace dlslot::detector {

struct GroundModel {
  int sectors = 0, bins = 0;
  double bin_m = 1.0;
  std::vector<float> height;   // ground z (lidar frame) per cell sector * bins + bin
  std::vector<uint8_t> fitted;  // 1 where the cell's own points continued the ground
  // Ground z under a lidar-frame xy (nearest cell; the last bin beyond the grid).
  float heightAt(float x, float y) const;
};

// Fits the ground of every sector from the lowest point of each cell.
GroundModel fitGround(const PointCloud& scan, const ScanLayout& layout, const ScanWindow& window,
                      const GroundConfig& cfg);

// Per point: 1 for an obstacle point (height above its cell's ground in (height_threshold_m,
// max_height_m]), 0 for ground, overhangs and unused points.
std::vector<uint8_t> obstacleMask(const PointCloud& scan, const ScanLayout& layout, const GroundModel& ground,
                                  const GroundConfig& cfg);

}  // namespace dlslot::detector
