// dlslot-sim's C++ API: make a synthetic KITTI tracking sequence with exact ground truth.
//
// Layout written under out_dir (sequence SSSS, frames NNNNNN):
//   training/velodyne/SSSS/NNNNNN.bin   scans (float32 x y z reflectance, lidar frame)
//   training/label_02/SSSS.txt          labels (KITTI tracking; every object in lidar range, not
//                                       only the camera's view; DontCare rows keep their 3D box)
//   training/calib/SSSS.txt             a real KITTI calibration (P0..P3, R_rect, Tr_velo_cam, Tr_imu_velo)
//   training/oxts/SSSS.txt              GPS/IMU records
//   training/poses/SSSS.txt             T_world_lidar, KITTI 3x4 rows, world = first scan's lidar frame
//   detections/sim/SSSS.txt             simulated detections (tracking format + score)
//   scenario.yaml                       the scenario with the seed and frame count used
//   lidar.yaml                          how the scans were stored: the pipeline config's `lidar`
//                                       section for them (dlslot-run --scenario merges it)
#pragma once

#include <cstdint>
#include <string>

#include "scenario.hpp"

namespace dlslot::sim {

struct SequenceStats {
  int frames = 0;
  double seconds = 0;        // wall time
  double mean_points = 0;    // per scan
  int objects = 0;           // moving and parked objects in the world
  int removed = 0;           // objects dropped because their paths would overlap
  int labelled_tracks = 0;   // track ids given
  double path_length_m = 0;  // of the ego
  int ego_path_end_frame = -1;  // Motion::ego_path_end_frame
};

struct WriteOptions {
  int threads = 1;
  bool progress = false;  // a progress line on stderr
  // Also write the sequence as a folder of your-own-data input (OUT/pcd/: NNNNNN.pcd, times.txt,
  // poses.txt of the vehicle, calib.yaml; procs/player/scan_folder.hpp).
  bool pcd_folder = false;
};

// Writes `frames` frames of the scenario from `seed` (both override the scenario's own).
SequenceStats writeSequence(const Scenario& scenario, int frames, uint64_t seed, const std::string& out_dir,
                            const std::string& sequence = "0000", const WriteOptions& options = {});

}  // namespace dlslot::sim
