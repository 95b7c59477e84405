#include "dlslot/convert.hpp"

#include <cmath>

namespace dlslot {

pose_t toMsg(const Pose& T) {
  pose_t m;
  const Eigen::Quaterniond q(T.linear());
  for (int i = 0; i < 3; ++i) m.position[i] = T.translation()[i];
  m.orientation[0] = q.w();
  m.orientation[1] = q.x();
  m.orientation[2] = q.y();
  m.orientation[3] = q.z();
  return m;
}

Pose fromMsg(const pose_t& m) {
  Eigen::Quaterniond q(m.orientation[0], m.orientation[1], m.orientation[2], m.orientation[3]);
  if (q.norm() < 1e-12) q = Eigen::Quaterniond::Identity();
  Pose T = Pose::Identity();
  T.linear() = q.normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(m.position[0], m.position[1], m.position[2]);
  return T;
}

box_t toMsg(const Box& b) {
  box_t m;
  m.type = b.type;
  m.id = b.id;
  m.score = b.score;
  for (int i = 0; i < 3; ++i) {
    m.center[i] = b.center[i];
    m.size[i] = b.size[i];
  }
  m.yaw = b.yaw;
  return m;
}

Box fromMsg(const box_t& m) {
  Box b;
  b.type = m.type;
  b.id = m.id;
  b.score = m.score;
  b.center = Eigen::Vector3d(m.center[0], m.center[1], m.center[2]);
  b.size = Eigen::Vector3d(m.size[0], m.size[1], m.size[2]);
  b.yaw = m.yaw;
  return b;
}

std::vector<box_t> toMsg(const std::vector<Box>& boxes) {
  std::vector<box_t> out;
  out.reserve(boxes.size());
  for (const Box& b : boxes) out.push_back(toMsg(b));
  return out;
}

std::vector<Box> fromMsg(const std::vector<box_t>& boxes) {
  std::vector<Box> out;
  out.reserve(boxes.size());
  for (const box_t& b : boxes) out.push_back(fromMsg(b));
  return out;
}

void toMsg(const Matrix6d& cov, double out[36]) {
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) out[r * 6 + c] = cov(r, c);
}

Matrix6d covFromMsg(const double in[36]) {
  Matrix6d cov;
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) cov(r, c) = in[r * 6 + c];
  return cov;
}

void toMsg(const PointCloud& scan, point_cloud_t& out) {
  const Eigen::Index n = scan.cols();
  out.num_points = static_cast<int32_t>(n);
  out.x.resize(n);
  out.y.resize(n);
  out.z.resize(n);
  out.intensity.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    out.x[i] = scan(0, i);
    out.y[i] = scan(1, i);
    out.z[i] = scan(2, i);
    out.intensity[i] = scan(3, i);
  }
}

PointCloud fromMsg(const point_cloud_t& m) {
  PointCloud scan(4, m.num_points);
  for (int i = 0; i < m.num_points; ++i) scan.col(i) << m.x[i], m.y[i], m.z[i], m.intensity[i];
  return scan;
}

std::vector<stage_timing_t> toMsg(const StageTimings& t) {
  std::vector<stage_timing_t> out;
  for (const auto& [name, ms] : t) {
    stage_timing_t s;
    s.name = name;
    s.ms = ms;
    out.push_back(s);
  }
  return out;
}

StageTimings fromMsg(const std::vector<stage_timing_t>& t) {
  StageTimings out;
  for (const auto& s : t) out.emplace_back(s.name, s.ms);
  return out;
}

bool isValid(const box_t& b) {
  for (int i = 0; i < 3; ++i)
    if (!std::isfinite(b.center[i]) || !std::isfinite(b.size[i]) || b.size[i] <= 0) return false;
  return std::isfinite(b.yaw) && std::isfinite(b.score);
}

}  // namespace dlslot
