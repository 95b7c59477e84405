// Constructed scans for the odometry tests: a small ray caster over rectangles (walls, poles)
// and an optional ground plane, with the HDL-64E's beam elevations, so scans have exactly
// known geometry and are taken from exactly known poses.
#pragma once

#include <cmath>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include "dlslot/types.hpp"

namespace dlslot::odometry::test {

// A rectangle centred at `center`, spanned by unit vectors u and v, half sizes half_u, half_v.
struct Rect {
  Eigen::Vector3d center, u, v;
  double half_u, half_v;
};

// A vertical wall from a to b (xy), from z0 to z1.
inline Rect wall(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double z0, double z1) {
  const Eigen::Vector2d mid = 0.5 * (a + b);
  const Eigen::Vector2d dir = (b - a).normalized();
  return {Eigen::Vector3d(mid.x(), mid.y(), 0.5 * (z0 + z1)), Eigen::Vector3d(dir.x(), dir.y(), 0),
          Eigen::Vector3d::UnitZ(), 0.5 * (b - a).norm(), 0.5 * (z1 - z0)};
}

// The four faces of a vertical box (a pole or a parked-car-like block).
inline std::vector<Rect> pillar(const Eigen::Vector2d& c, double half_size, double z0, double z1) {
  const double h = half_size;
  const Eigen::Vector2d p0 = c + Eigen::Vector2d(-h, -h), p1 = c + Eigen::Vector2d(h, -h),
                        p2 = c + Eigen::Vector2d(h, h), p3 = c + Eigen::Vector2d(-h, h);
  return {wall(p0, p1, z0, z1), wall(p1, p2, z0, z1), wall(p2, p3, z0, z1), wall(p3, p0, z0, z1)};
}

// HDL-64E elevations (degrees, beam 0 highest): +2.0 .. -8.33 in 1/3 deg, -8.83 .. -24.33 in 1/2 deg.
inline std::vector<double> hdl64ElevationsDeg() {
  std::vector<double> e;
  for (int i = 0; i < 32; ++i) e.push_back(2.0 - i / 3.0);
  for (int i = 0; i < 32; ++i) e.push_back(-8.83 - 0.5 * i);
  return e;
}

struct Scene {
  std::vector<Rect> rects;
  std::optional<double> ground_z;  // world z of a horizontal ground plane

  void add(const std::vector<Rect>& rs) { rects.insert(rects.end(), rs.begin(), rs.end()); }

  // Range along the ray (world frame) to the nearest surface, or infinity.
  double cast(const Eigen::Vector3d& o, const Eigen::Vector3d& d) const {
    double best = std::numeric_limits<double>::infinity();
    if (ground_z && d.z() < -1e-9) best = (*ground_z - o.z()) / d.z();
    for (const Rect& r : rects) {
      const Eigen::Vector3d n = r.u.cross(r.v);
      const double den = n.dot(d);
      if (std::abs(den) < 1e-12) continue;
      const double t = n.dot(r.center - o) / den;
      if (t <= 0 || t >= best) continue;
      const Eigen::Vector3d q = o + t * d - r.center;
      if (std::abs(q.dot(r.u)) <= r.half_u && std::abs(q.dot(r.v)) <= r.half_v) best = t;
    }
    return best;
  }

  // A scan from T_world_lidar: rings from the top beam, each counter-clockwise from straight ahead
  // (the KITTI order), lidar frame, intensity 0.5. Rays hitting nothing within max_range give no point.
  PointCloud scan(const Pose& T_world_lidar, int azimuth_steps = 1800, double max_range = 80.0) const {
    std::vector<Eigen::Vector4f> pts;
    const Eigen::Vector3d o = T_world_lidar.translation();
    for (double elev_deg : hdl64ElevationsDeg()) {
      const double el = elev_deg * M_PI / 180.0;
      for (int k = 0; k < azimuth_steps; ++k) {
        const double az = 2.0 * M_PI * k / azimuth_steps;
        const Eigen::Vector3d d_lidar(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
        const double t = cast(o, T_world_lidar.linear() * d_lidar);
        if (t > max_range) continue;
        const Eigen::Vector3d p = t * d_lidar;
        pts.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()), 0.5f);
      }
    }
    PointCloud cloud(4, static_cast<Eigen::Index>(pts.size()));
    for (size_t i = 0; i < pts.size(); ++i) cloud.col(static_cast<Eigen::Index>(i)) = pts[i];
    return cloud;
  }
};

// A street along +x: ground, building facades on both sides broken by side streets, a cross wall
// far ahead and behind, poles along the kerbs. Every direction of motion is constrained.
inline Scene street() {
  Scene s;
  s.ground_z = -1.73;  // KITTI's lidar height
  for (double x0 = -60; x0 < 140; x0 += 25) {
    s.rects.push_back(wall({x0, 9.0}, {x0 + 18, 9.0}, -1.73, 10.0));
    s.rects.push_back(wall({x0 + 7, -10.0}, {x0 + 23, -10.0}, -1.73, 8.0));
    s.rects.push_back(wall({x0 + 18, 9.0}, {x0 + 18, 16.0}, -1.73, 10.0));      // side-street corner
    s.rects.push_back(wall({x0 + 23, -10.0}, {x0 + 23, -17.0}, -1.73, 8.0));
  }
  for (double x = -50; x < 140; x += 12) {
    s.add(pillar({x, 6.5}, 0.15, -1.73, 4.0));
    s.add(pillar({x + 6, -7.5}, 0.15, -1.73, 4.0));
  }
  s.rects.push_back(wall({150, -30}, {150, 30}, -1.73, 12.0));
  s.rects.push_back(wall({-70, -30}, {-70, 30}, -1.73, 12.0));
  return s;
}

inline Pose planarPose(double x, double y, double yaw_rad) {
  Pose T = Pose::Identity();
  T.linear() = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, 0.0);
  return T;
}

// A frame of the odometry's input: scan number `index`, no detections.
inline Frame frameOf(int index, PointCloud scan) {
  Frame f;
  f.index = index;
  f.scan = std::move(scan);
  return f;
}

}  // namespace dlslot::odometry::test
