// The odometry without LCM: reads a KITTI sequence directly, writes the trajectory in the KITTI
// 3x4 pose format and prints the time per stage. For measuring accuracy and speed.
#pragma once

#include <string>
#include <vector>

#include "odometry_config.hpp"

namespace dlslot::odometry {

struct OfflineOptions {
  std::string root, sequence, out;
  std::vector<std::string> detections;
  double min_detection_score = -1e300;
  double frame_period_s = 0.1;
  bool quiet = false;
};

// Returns the process exit code.
int runOffline(const OfflineOptions& opts, const OdometryConfig& cfg);

}  // namespace dlslot::odometry
