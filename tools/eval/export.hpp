// Writing a run's tracks in the KITTI tracking result format, so other tools (the KITTI devkit,
// TrackEval) can score them. Trajectories are written with writeTrajectory (trajectory.hpp).
#pragma once

#include <string>
#include <vector>

#include "dlslot/kitti.hpp"

namespace dlslot::eval {

struct FrameTracks {
  int frame = 0;
  std::vector<Box> boxes;  // lidar frame of the scan, id = track id
};

// One line per track and frame: frame id type 0 0 alpha x1 y1 x2 y2 h w l x y z rotation_y score,
// in the rectified camera frame (bottom centre), built by kitti::resultRow: the 2-D box is the box
// projected with P2 and clipped to the image. Boxes not in the camera image are left out (the
// devkit scores only what the camera sees). Throws when the calibration has no P2.
struct ExportCount {
  int written = 0, outside_image = 0;
};
ExportCount writeKittiTracks(const std::string& path, const std::vector<FrameTracks>& frames, const kitti::Calib& calib,
                             const kitti::ImageSize& image = {});

// Reads the same format back (labels or results) into lidar-frame boxes for frames 0..num_frames-1;
// DontCare rows go to `dontcare` when given.
std::vector<FrameTracks> readKittiTracks(const std::string& path, const kitti::Calib& calib, int num_frames,
                                         std::vector<FrameTracks>* dontcare = nullptr);

}  // namespace dlslot::eval
