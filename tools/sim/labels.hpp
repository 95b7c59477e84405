// Ground-truth label rows in the KITTI tracking format: the box in the rectified camera frame
// (bottom centre, rotation_y, through the calibration), its 2D box in the image of camera 2
// (projected with P2 and clipped; -1 -1 -1 -1 for objects the camera does not see), how much of
// it lies outside the image (truncated) and how much of it other things hide (occluded).
//
// Unlike KITTI, which labels only what the camera sees, every object within the lidar's range is
// labelled: the evaluation is 360 deg in bird's-eye view.
#pragma once

#include <optional>

#include "dlslot/kitti.hpp"
#include "sensor.hpp"

namespace dlslot::sim {

struct ImageBox {
  Eigen::Vector4d bbox;  // left top right bottom, pixels, clipped to the image
  double truncated;      // 1 - clipped area / unclipped area
};
// The box's projection into camera 2, or nullopt when no part of it is in front of the camera and
// inside the image.
std::optional<ImageBox> projectToImage(const Box& box_lidar, const kitti::Calib& calib);

// KITTI occlusion level from how many of the rays reaching the box something else stopped:
// 0 fully visible (< 10 %), 1 partly (< 50 %), 2 largely occluded, 3 unknown (no ray reached it).
int occlusionLevel(const ObjectView& view);

// A label row (no score) for a box in the lidar frame.
kitti::LabelRow labelRow(int frame, int track_id, const std::string& type, const Box& box_lidar,
                         const kitti::Calib& calib, int occluded);

}  // namespace dlslot::sim
