// The mapper's files in the run folder: map.pcd and map_removed.pcd (binary PCD, x y z
// intensity, one point per voxel), map.png (top-down, coloured by height, with the loop-closed
// trajectory and the accepted loop edges), trajectory_map_{kitti,tum}.txt (every scan's
// loop-closed pose, the formats of the other trajectories), map_keyframes.txt and map_loops.txt
// (for dlslot-eval --map).
#pragma once

#include <string>

#include "mapper/mapper.hpp"

namespace dlslot::mapper {

// Binary PCD with fields x y z intensity (PCL's writer); throws naming the file on failure.
void writePcd(const std::string& path, const PointCloud& points);
// Reads a PCD written by writePcd (or any with x y z, intensity optional).
PointCloud readPcd(const std::string& path);

struct MapImageStats {
  int width = 0, height = 0;
  double metres_per_pixel = 0;
};
MapImageStats writeMapImage(const std::string& path, const Mapper& mapper, int max_side_px = 2000);

// Writes every file above into dir; returns the list of names written.
std::vector<std::string> writeMapOutputs(const std::string& dir, const Mapper& mapper);

}  // namespace dlslot::mapper
