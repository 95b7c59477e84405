#include "oxts.hpp"

#include <algorithm>

namespace dlslot::sim {

std::vector<kitti::OxtsRecord> simulatedOxts(const std::vector<Pose>& T_world_lidar, const Pose& T_velo_imu,
                                             double dt) {
  std::vector<kitti::OxtsRecord> rows = kitti::lidarPosesToOxts(T_world_lidar, T_velo_imu, kLat0, kLon0, kAlt0);
  const int n = static_cast<int>(T_world_lidar.size());
  if (n < 2) return rows;
  // The oxts world is east-north-up with the first lidar frame's axes (lidarPosesToOxts only shifts).
  std::vector<Pose> imu;
  for (const Pose& P : T_world_lidar) imu.push_back(P * T_velo_imu);
  auto position = [&](int k) { return imu[std::clamp(k, 0, n - 1)].translation(); };
  for (int k = 0; k < n; ++k) {
    const int a = std::max(0, k - 1), b = std::min(n - 1, k + 1);
    const Eigen::Matrix3d R = imu[k].linear();
    const Eigen::Vector3d v = (position(b) - position(a)) / ((b - a) * dt);
    const int m = n >= 3 ? std::clamp(k, 1, n - 2) : k;  // second differences need both neighbours
    const Eigen::Vector3d acc = (position(m + 1) - 2 * position(m) + position(m - 1)) / (dt * dt);
    const Eigen::Vector3d f_body = R.transpose() * (acc + Eigen::Vector3d(0, 0, 9.81));
    const Eigen::Vector3d v_body = R.transpose() * v;
    const Eigen::AngleAxisd turn(imu[a].linear().transpose() * imu[b].linear());
    const Eigen::Vector3d w_body = turn.angle() * turn.axis() / ((b - a) * dt);
    kitti::OxtsRecord& r = rows[k];
    r[6] = v.y();  // vn
    r[7] = v.x();  // ve
    for (int i = 0; i < 3; ++i) {
      r[8 + i] = v_body[i];   // vf vl vu
      r[11 + i] = f_body[i];  // ax ay az
      r[14 + i] = f_body[i];  // af al au
      r[17 + i] = w_body[i];  // wx wy wz
      r[20 + i] = w_body[i];  // wf wl wu
    }
    r[23] = 0.05;  // posacc, m
    r[24] = 0.02;  // velacc, m/s
  }
  return rows;
}

}  // namespace dlslot::sim
