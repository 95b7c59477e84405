// The HDL-64E-like lidar: 64 beams at the HDL-64E's vertical angles, `azimuth_steps`
// columns a revolution, intensity from the surface's reflectivity and the angle of incidence; with
// a real one's imperfections (sensor_model.hpp, each switchable in the scenario): a firing phase that changes every revolution, per-beam calibration residuals (the rays leave at
// angles the stored points do not have), range noise growing with range and incidence, weak
// returns lost, motion distortion (each column fired at its time in the 0.1 s sweep while the ego
// and the objects move) and porous foliage and fences. Points are written ring by ring from the
// top beam, each ring counter-clockwise from straight ahead, like a KITTI velodyne scan.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "dlslot/types.hpp"
#include "sensor_model.hpp"
#include "world.hpp"

namespace dlslot::sim {

constexpr int kBeams = 64;
// Elevation of each beam in degrees, beam 0 the highest: the upper block +2.0 .. -8.33 in 1/3 deg
// steps, the lower block -8.83 .. -24.33 in 1/2 deg steps.
double beamElevationDeg(int beam);
// The beam A-LOAM's scanRegistration assigns to a point of this elevation for a 64-beam lidar.
int aloamBeam(double elevation_deg);

// KITTI-like reflectance of the ground's surfaces.
float groundReflectivity(Surface s);

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
  Pose T_map_lidar = Pose::Identity();  // at the scan's reference time (lidar facing ahead)
  SweepMotion ego;                      // the lidar's motion over the sweep (ego.T_ref == T_map_lidar)
  double period_s = 0.1;                // one revolution
  std::vector<Solid> object_solids;     // map frame at the reference time, owner = object index
  std::vector<Box> object_boxes;        // map frame, per object (for visibility counts)
  std::vector<Eigen::Vector3d> object_velocity;  // map frame, per object (empty: all standing)
  std::array<BeamError, kBeams> beam_errors{};   // the sensor's calibration residuals
  uint64_t key = 0;                              // random stream of this frame
};

Scan scan(const SensorSpec& sensor, const ScanInput& in, int threads = 1);

}  // namespace dlslot::sim
