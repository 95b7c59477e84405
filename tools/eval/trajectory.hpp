// An ego trajectory (one pose per scan) and its file formats: KITTI 3x4 rows in the lidar frame,
// the same in the camera-0 frame (the KITTI odometry benchmark's convention), and TUM.
#pragma once

#include <istream>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "dlslot/types.hpp"

namespace dlslot::eval {

struct Trajectory {
  std::vector<int> frames;     // scan indices, increasing
  std::vector<double> stamps;  // seconds
  std::vector<Pose> poses;     // T_world_lidar
  size_t size() const { return poses.size(); }
  bool empty() const { return poses.empty(); }
  void add(int frame, double stamp, const Pose& T);
};

// Restricts both trajectories to the frames they have in common.
std::pair<Trajectory, Trajectory> commonFrames(const Trajectory& a, const Trajectory& b);

// The ground truth in the estimate's world. A run that starts later in the sequence than the
// ground truth has its world at its own first scan: then the ground truth is re-expressed so that
// it coincides with `est` at est's first frame, G'_i = P_0 inv(G_0) G_i (relative errors are
// unchanged). Otherwise `gt` is returned as it is.
Trajectory inWorldOf(const Trajectory& gt, const Trajectory& est);

// kitti: T_world_lidar as 3x4 rows. kitti_cam: camera-0 poses T_cam = Tr * T * inv(Tr) with
// Tr = T_cam_velo (as KITTI's odometry ground truth). tum: "stamp tx ty tz qx qy qz qw".
enum class TrajectoryFormat { Kitti, KittiCam, Tum };
TrajectoryFormat parseTrajectoryFormat(const std::string& name);  // throws std::invalid_argument
std::string formatName(TrajectoryFormat format);

// Frames are numbered 0.. in file order; KITTI files get stamps frame * frame_period_s.
// kitti_cam needs T_cam_velo. Throws InputError naming the file and line.
Trajectory readTrajectory(const std::string& path, TrajectoryFormat format,
                          const std::optional<Pose>& T_cam_velo = std::nullopt, double frame_period_s = 0.1);
// The tum format from an open stream (readTrajectory opens the file); `path` names it in errors.
Trajectory readTum(std::istream& in, const std::string& path);
void writeTrajectory(const std::string& path, const Trajectory& trajectory, TrajectoryFormat format,
                     const std::optional<Pose>& T_cam_velo = std::nullopt);

}  // namespace dlslot::eval
