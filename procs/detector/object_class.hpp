// A class, a completed box and a score for one cluster, from its size and shape alone.
//
// Classes: Car, Van, Truck, Pedestrian, Cyclist (KITTI names), "Unknown" for an object-sized
// cluster no class fits (published so the odometry removes its points, never tracked: no tracker
// class holds that type, see dlslot::kUnknownType in types.hpp), and background (poles, walls, overhangs, anything
// larger than an object: not published, the odometry keeps those points).
#pragma once

#include <optional>
#include <string>

#include "detector/detector_config.hpp"
#include "dlslot/types.hpp"
#include "detector/rectangle_fit.hpp"

namespace dlslot::detector {

// What the detector measured of one cluster (lidar frame).
struct ClusterShape {
  Rectangle seen;           // bird's-eye rectangle of its points
  double ground_z = 0;      // ground under it
  double min_z = 0, max_z = 0;
  double max_tan = 0;       // highest elevation (z / horizontal range) of its points
  int num_points = 0;
  // Height profile along the seen length: highest point of each quarter, highest minus lowest
  // quarter. A vehicle's bonnet and boot sit below its roof; walls and barriers are level.
  double profile_step = 0.0;
};

// A vehicle's rectangle completed to at least the prior size when only part of it was seen. The
// seen face nearest the sensor stays where it is and the box grows away from the sensor (at the
// origin). A face no wider than a car's back seen across the line of sight is the vehicle's back
// or front, so its length axis is turned to run across that face.
Rectangle completeVehicle(const Rectangle& seen, double prior_length_m, double prior_width_m, double side_min_m);

// The detection for a cluster: a box (centre at half its height above the ground) with a KITTI
// type or kUnknownType and a score (logit of a confidence in (0, 1), the scale of
// tracker.score_scale: logit); nullopt for background.
std::optional<Box> classifyCluster(const ClusterShape& shape, const ClassConfig& cfg);

}  // namespace dlslot::detector
