#include "trajectory.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "dlslot/input_error.hpp"
#include "dlslot/kitti.hpp"

namespace dlslot::eval {

void Trajectory::add(int frame, double stamp, const Pose& T) {
  frames.push_back(frame);
  stamps.push_back(stamp);
  poses.push_back(T);
}

std::pair<Trajectory, Trajectory> commonFrames(const Trajectory& a, const Trajectory& b) {
  Trajectory ca, cb;
  size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (a.frames[i] < b.frames[j]) {
      ++i;
    } else if (b.frames[j] < a.frames[i]) {
      ++j;
    } else {
      ca.add(a.frames[i], a.stamps[i], a.poses[i]);
      cb.add(b.frames[j], b.stamps[j], b.poses[j]);
      ++i, ++j;
    }
  }
  return {ca, cb};
}

Trajectory inWorldOf(const Trajectory& gt, const Trajectory& est) {
  if (est.empty() || gt.empty() || gt.frames[0] >= est.frames[0]) return gt;
  for (size_t i = 0; i < gt.size(); ++i)
    if (gt.frames[i] == est.frames[0]) {
      const Pose change = est.poses[0] * gt.poses[i].inverse();
      Trajectory out = gt;
      for (Pose& T : out.poses) T = change * T;
      return out;
    }
  throw std::invalid_argument("the ground truth has no pose for frame " + std::to_string(est.frames[0]));
}

TrajectoryFormat parseTrajectoryFormat(const std::string& name) {
  if (name == "kitti") return TrajectoryFormat::Kitti;
  if (name == "kitti_cam") return TrajectoryFormat::KittiCam;
  if (name == "tum") return TrajectoryFormat::Tum;
  throw std::invalid_argument("trajectory format '" + name + "': expected kitti, kitti_cam or tum");
}

std::string formatName(TrajectoryFormat format) {
  switch (format) {
    case TrajectoryFormat::Kitti: return "kitti";
    case TrajectoryFormat::KittiCam: return "kitti_cam";
    case TrajectoryFormat::Tum: return "tum";
  }
  return "";
}

namespace {

const Pose& needCalib(const std::optional<Pose>& T_cam_velo, const std::string& path) {
  if (!T_cam_velo)
    throw InputError(path, 0, "the kitti_cam format needs the calibration (Tr_velo_cam): give --kitti ROOT --sequence S or --calib FILE");
  return *T_cam_velo;
}

}  // namespace

Trajectory readTum(std::istream& in, const std::string& path) {
  Trajectory t;
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    const size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream is(line);
    double v[8];
    int k = 0;
    while (k < 8 && is >> v[k]) ++k;
    std::string extra;
    if (k != 8 || (is >> extra))
      throw InputError(path, n, "expected 8 numbers (timestamp tx ty tz qx qy qz qw)");
    for (double x : v)
      if (!std::isfinite(x)) throw InputError(path, n, "expected finite numbers");
    const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    if (std::abs(q.norm() - 1.0) > 1e-3)
      throw InputError(path, n, "quaternion norm " + std::to_string(q.norm()) + ", expected 1");
    Pose T = Pose::Identity();
    T.linear() = q.normalized().toRotationMatrix();
    T.translation() << v[1], v[2], v[3];
    t.add(static_cast<int>(t.size()), v[0], T);
  }
  return t;
}

Trajectory readTrajectory(const std::string& path, TrajectoryFormat format, const std::optional<Pose>& T_cam_velo,
                          double frame_period_s) {
  if (format == TrajectoryFormat::Tum) {
    std::ifstream in(path);
    if (!in) throw InputError(path, 0, "cannot open for reading");
    return readTum(in, path);
  }
  std::vector<Pose> poses = kitti::readPoses(path);
  if (format == TrajectoryFormat::KittiCam) {
    const Pose& Tr = needCalib(T_cam_velo, path);
    for (Pose& T : poses) T = Tr.inverse() * T * Tr;
  }
  Trajectory t;
  for (size_t i = 0; i < poses.size(); ++i) t.add(static_cast<int>(i), i * frame_period_s, poses[i]);
  return t;
}

void writeTrajectory(const std::string& path, const Trajectory& trajectory, TrajectoryFormat format,
                     const std::optional<Pose>& T_cam_velo) {
  if (format != TrajectoryFormat::Tum) {
    std::vector<Pose> poses = trajectory.poses;
    if (format == TrajectoryFormat::KittiCam) {
      const Pose& Tr = needCalib(T_cam_velo, path);
      for (Pose& T : poses) T = Tr * T * Tr.inverse();
    }
    kitti::writePoses(path, poses);
    return;
  }
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) throw InputError(path, 0, "cannot open for writing");
  std::fprintf(f, "# timestamp tx ty tz qx qy qz qw (T_world_lidar)\n");
  for (size_t i = 0; i < trajectory.size(); ++i) {
    const Pose& T = trajectory.poses[i];
    const Eigen::Quaterniond q(T.linear());
    std::fprintf(f, "%.6f %.9f %.9f %.9f %.12f %.12f %.12f %.12f\n", trajectory.stamps[i], T.translation().x(),
                 T.translation().y(), T.translation().z(), q.x(), q.y(), q.z(), q.w());
  }
  if (std::fclose(f) != 0) throw InputError(path, 0, "write failed");
}

}  // namespace dlslot::eval
