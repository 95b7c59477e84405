// Plain types shared by every core: poses, boxes, scans. No LCM here.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace dlslot {

// A rigid transform T_parent_child (e.g. T_world_lidar maps lidar-frame points to the world).
using Pose = Eigen::Isometry3d;

// One scan: a column per point, rows x y z intensity, lidar frame (same memory layout as a
// KITTI velodyne .bin, so reading and writing is one copy).
using PointCloud = Eigen::Matrix<float, 4, Eigen::Dynamic>;

// An oriented box: geometric centre, size (l along the heading, w, h), yaw about +z.
struct Box;

// A box's containment test with its yaw's cosine and sine taken once, for many points against one
// box (Box::contains makes one per call; in the box filter a per-call sincos was 15 % of the
// backend's time). The box grown by `margin` on every side.
struct BoxContainment {
  BoxContainment(const Box& b, double margin);
  bool contains(double px, double py, double pz) const {
    const double dx = px - x, dy = py - y;
    if (dx * dx + dy * dy > r2) return false;  // outside its bounding circle: most points
    return std::abs(c * dx + s * dy) <= hx && std::abs(-s * dx + c * dy) <= hy && std::abs(pz - z) <= hz;
  }
  double x, y, z, c, s, hx, hy, hz;
  double r2;  // squared radius of its bounding circle (half the grown diagonal, bird's-eye)
};

struct Box {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  Eigen::Vector3d size = Eigen::Vector3d::Zero();  // l, w, h
  double yaw = 0.0;
  std::string type;  // KITTI class name
  int id = -1;       // track id, -1 when unknown
  double score = 1.0;

  // T_frame_box: the box's own frame (x along the heading) in the frame the box is given in.
  Pose pose() const;
  // The same box with T_new_frame applied (centre moved, yaw rotated about z).
  Box transformed(const Pose& T_new_frame) const;
  // True when p (same frame as the box) lies inside the box grown by `margin` on every side.
  bool contains(const Eigen::Vector3d& p, double margin = 0.0) const;
};

// The type of a detected box no class fits (dlslot-detector): published so the odometry removes
// its points, never tracked (the tracker refuses it as a class type).
inline constexpr const char* kUnknownType = "Unknown";

// Everything the data set has for one scan.
struct Frame {
  int index = 0;
  int64_t utime = 0;
  PointCloud scan;
  std::vector<Box> detections;        // lidar frame
  std::vector<Box> labels;            // lidar frame, DontCare excluded
  std::vector<Box> dontcare;          // lidar frame
  std::optional<Pose> gt_pose;        // T_world_lidar
};

// Yaw of a rotation (heading of its x axis in the xy plane).
double yawOf(const Eigen::Matrix3d& R);
// Wraps an angle to (-pi, pi].
double wrapAngle(double a);

}  // namespace dlslot
