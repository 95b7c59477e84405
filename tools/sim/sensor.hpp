// The HDL-64E-like lidar (issue 3): 64 beams at the HDL-64E's vertical angles, `azimuth_steps`
// columns a revolution, instantaneous scans (no motion distortion, like de-skewed KITTI),
// Gaussian range noise, random and range-dependent dropouts, intensity from the surface's
// reflectivity and the angle of incidence. Points are written ring by ring from the top beam,
// each ring counter-clockwise from straight ahead, like a KITTI velodyne scan.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "dlslot/types.hpp"
#include "world.hpp"

namespace dlslot::sim {

constexpr int kBeams = 64;
// Elevation of each beam in degrees, beam 0 the highest: the upper block +2.0 .. -8.33 in 1/3 deg
// steps, the lower block -8.83 .. -24.33 in 1/2 deg steps.
double beamElevationDeg(int beam);
// The beam A-LOAM's scanRegistration assigns to a point of this elevation for a 64-beam lidar.
int aloamBeam(double elevation_deg);

struct ObjectView {
  int points = 0;   // returns from the object
  int rays = 0;     // rays that reach its box (not stopped by the ground first)
  int blocked = 0;  // of those, stopped by something else before the box
};

struct Scan {
  PointCloud points;              // lidar frame
  std::vector<uint8_t> beam;      // per point
  std::vector<int32_t> object;    // per point: index of the object hit, or -1
  std::vector<int32_t> solid;     // per point: >= 0 static solid (World::grid), -1 ground,
                                  // <= -2 object solid -2 - k (of the objects' solids given to scan())
  std::vector<ObjectView> views;  // per object
};

struct ScanInput {
  const World* world = nullptr;
  Pose T_map_lidar = Pose::Identity();
  std::vector<Solid> object_solids;  // map frame, owner = object index
  std::vector<Box> object_boxes;     // map frame, per object (for visibility counts)
  uint64_t key = 0;                  // random stream of this frame
};

Scan scan(const SensorSpec& sensor, const ScanInput& in, int threads = 1);

}  // namespace dlslot::sim
