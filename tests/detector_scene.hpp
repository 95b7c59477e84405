// Synthetic scans for the detector's tests: an HDL-64E-like lidar 1.73 m above a ground made of
// planes (a slope, a kerb) with boxes (vehicles, people) and vertical cylinders (poles) on it,
// ray-cast exactly (no noise), so every object's box is known.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "dlslot/types.hpp"

namespace dlslot::test {

struct DetectorScene {
  // Ground z at (x, y): -sensor_height + slope * x, plus kerb_height where y > kerb_y.
  double sensor_height = 1.73, slope = 0.0, kerb_y = 1e9, kerb_height = 0.0;
  std::vector<Box> boxes;  // lidar frame; centre z set by place()
  struct Pole {
    Eigen::Vector2d xy;
    double radius, height;
  };
  std::vector<Pole> poles;

  double groundZ(double x, double y) const { return -sensor_height + slope * x + (y > kerb_y ? kerb_height : 0.0); }
  // Adds a box standing on the ground at (x, y).
  Box& place(const std::string& type, double x, double y, double yaw, double l, double w, double h) {
    Box b;
    b.type = type;
    b.center = Eigen::Vector3d(x, y, groundZ(x, y) + 0.5 * h);
    b.size = Eigen::Vector3d(l, w, h);
    b.yaw = yaw;
    boxes.push_back(b);
    return boxes.back();
  }
  // A car standing at (x, y): a body to 60 % of its height and a cabin on it (half the length,
  // 85 % of the width), as a lidar sees one (a level box is a wall's shape). Returns its box.
  Box car(double x, double y, double yaw, double l, double w, double h) {
    const Box outer = place("Car", x, y, yaw, l, w, h);
    boxes.back().size.z() = 0.6 * h;
    boxes.back().center.z() = groundZ(x, y) + 0.3 * h;
    place("Car", x, y, yaw, 0.5 * l, 0.85 * w, h);
    return outer;
  }
  void pole(double x, double y, double radius, double height) { poles.push_back({{x, y}, radius, height}); }

  // The scan: 64 beams at the HDL-64E's elevations (+2 .. -24.9 deg), `azimuth_steps` a turn.
  PointCloud scan(int azimuth_steps = 2000, double max_range = 80.0) const {
    std::vector<Eigen::Vector4f> pts;
    for (int beam = 0; beam < 64; ++beam) {
      const double elev_deg = beam < 32 ? 2.0 - beam / 3.0 : -8.83 - (beam - 32) * 0.5;
      const double el = elev_deg * M_PI / 180;
      for (int a = 0; a < azimuth_steps; ++a) {
        const double az = 2 * M_PI * a / azimuth_steps;
        const Eigen::Vector3d d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
        double t = hit(d, max_range);
        if (t < max_range) {
          const Eigen::Vector3d p = t * d;
          pts.emplace_back(p.x(), p.y(), p.z(), 0.5f);
        }
      }
    }
    PointCloud c(4, static_cast<int>(pts.size()));
    for (size_t i = 0; i < pts.size(); ++i) c.col(static_cast<int>(i)) = pts[i];
    return c;
  }

 private:
  // Distance along the unit ray d from the origin to the first surface, or max_range.
  double hit(const Eigen::Vector3d& d, double max_range) const {
    double best = max_range;
    // Ground planes: z = -h + slope x (+ kerb); a hit counts when it lies in the plane's region.
    for (const double k : {0.0, kerb_height}) {
      if (k != 0.0 && kerb_height == 0.0) continue;
      const double denom = d.z() - slope * d.x();
      if (std::abs(denom) < 1e-9) continue;
      const double t = (-sensor_height + k) / denom;
      if (t <= 0 || t >= best) continue;
      const bool on_kerb_side = (t * d).y() > kerb_y;
      if (kerb_height == 0.0 || on_kerb_side == (k != 0.0)) best = t;
    }
    // Kerb face: the vertical plane y = kerb_y between the two ground levels.
    if (kerb_height > 0 && std::abs(d.y()) > 1e-9) {
      const double t = kerb_y / d.y();
      if (t > 0 && t < best) {
        const Eigen::Vector3d p = t * d;
        const double g = -sensor_height + slope * p.x();
        if (p.z() >= g && p.z() <= g + kerb_height) best = t;
      }
    }
    for (const Box& b : boxes) {  // slab test in the box's frame
      const Eigen::Matrix3d R = Eigen::AngleAxisd(b.yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
      const Eigen::Vector3d o = R.transpose() * (-b.center), dir = R.transpose() * d;
      double t0 = 0, t1 = best;
      bool miss = false;
      for (int k = 0; k < 3 && !miss; ++k) {
        const double half = 0.5 * b.size[k];
        if (std::abs(dir[k]) < 1e-12) {
          miss = std::abs(o[k]) > half;
          continue;
        }
        double a = (-half - o[k]) / dir[k], c = (half - o[k]) / dir[k];
        if (a > c) std::swap(a, c);
        t0 = std::max(t0, a);
        t1 = std::min(t1, c);
        miss = t0 > t1;
      }
      if (!miss && t0 > 0 && t0 < best) best = t0;
    }
    for (const Pole& p : poles) {  // vertical cylinder from the ground up
      const Eigen::Vector2d dxy = d.head<2>();
      const double a = dxy.squaredNorm(), bq = -2 * dxy.dot(p.xy), c = p.xy.squaredNorm() - p.radius * p.radius;
      const double disc = bq * bq - 4 * a * c;
      if (a < 1e-12 || disc < 0) continue;
      const double t = (-bq - std::sqrt(disc)) / (2 * a);
      if (t <= 0 || t >= best) continue;
      const double z = t * d.z(), g = groundZ(p.xy.x(), p.xy.y());
      if (z >= g && z <= g + p.height) best = t;
    }
    return best;
  }
};

}  // namespace dlslot::test
