// LIDAR_SCAN's bytes made straight from a PointCloud: the same bytes as point_cloud_t::encode
// (lcm-gen), without the message's own copy of the points and with a byte swap the compiler
// vectorizes (lcm-gen's encoder writes one byte at a time: 43 % of the player's CPU time).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "dlslot/types.hpp"

namespace dlslot {

// Writes the encoded point_cloud_t {utime, frame, sequence, the scan's points} into `out`
// (resized; its capacity is kept, so a buffer reused frame after frame is allocated once).
void encodeScan(const PointCloud& scan, int64_t utime, int32_t frame, const std::string& sequence,
                std::vector<uint8_t>& out);

}  // namespace dlslot
