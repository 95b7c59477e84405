// Oxts records for a simulated drive: poses through kitti::lidarPosesToOxts (so the player's
// oxts -> pose conversion recovers them), plus the velocities, accelerations (specific force,
// gravity included) and angular rates a real GPS/IMU would report, from finite differences.
#pragma once

#include <vector>

#include "dlslot/kitti.hpp"

namespace dlslot::sim {

// Where the simulated drives are (Karlsruhe, like KITTI).
constexpr double kLat0 = 49.011, kLon0 = 8.4235, kAlt0 = 115.0;

std::vector<kitti::OxtsRecord> simulatedOxts(const std::vector<Pose>& T_world_lidar, const Pose& T_velo_imu, double dt);

}  // namespace dlslot::sim
