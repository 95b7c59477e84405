// The calibration written with every simulated sequence: the values of a real KITTI tracking
// calibration (sequence 0000: cameras P0..P3, R_rect, Tr_velo_cam, Tr_imu_velo), so labels go
// through a realistic lidar -> camera transform and oxts through a realistic imu -> lidar one.
#pragma once

#include "dlslot/kitti.hpp"

namespace dlslot::sim {

kitti::Calib kittiCalib();

// The image the 2D boxes are projected into (KITTI's left colour camera, P2).
constexpr double kImageWidth = 1242.0, kImageHeight = 375.0;

}  // namespace dlslot::sim
