// A 64-beam lidar's points on a box-shaped object (and optionally the ground under it): what the
// per-object registration sees of a car, with the partial view and the ring pattern of a real
// scan (the two scans of a moving object hit different parts of it).
#pragma once

#include <cmath>
#include <random>
#include <vector>

#include "backend/object_registration.hpp"

namespace dlslot::backend::test {

// The lidar above the ground and a typical car (l, w, h) for the scenes of these tests.
inline const Eigen::Vector3d kSensor(0, 0, 1.73);
inline const Eigen::Vector3d kCar(4.5, 1.8, 1.5);

// The first hit of the ray from `origin` along `dir` with the box (its own frame: centred,
// half sizes `half`), if any.
inline bool rayBox(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, const Eigen::Vector3d& half, double* hit) {
  double t0 = 0, t1 = 1e9;
  for (int k = 0; k < 3; ++k) {
    if (std::abs(dir[k]) < 1e-12) {
      if (std::abs(origin[k]) > half[k]) return false;
      continue;
    }
    double a = (-half[k] - origin[k]) / dir[k], b = (half[k] - origin[k]) / dir[k];
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
  }
  if (t0 > t1 || t0 <= 0) return false;
  *hit = t0;
  return true;
}

// Points of a box of size `size` at T_world_box seen from a sensor at `sensor` (world, 1.7 m above
// the box floor's plane when z = 0 is the ground), range noise `noise` m. `ground`: also the
// ground (z = floor) within `ground_margin` m of the box footprint. The columns, 0.17 deg apart,
// start at the box's first bearing; with `column_phase` in [0, 1) they lie on the lidar's grid
// instead, shifted by that fraction of a column (a lidar's firing phase changes from scan to scan).
inline ObjectPoints scanBox(const Pose& T_world_box, const Eigen::Vector3d& size, const Eigen::Vector3d& sensor,
                            std::mt19937& rng, double noise = 0.01, bool ground = false, double ground_margin = 0.3,
                            double column_phase = -1.0) {
  std::normal_distribution<double> n(0.0, noise);
  const Eigen::Vector3d half = 0.5 * size;
  const Pose inv = T_world_box.inverse();
  const Eigen::Vector3d c = T_world_box.translation() - sensor;
  const double az_c = std::atan2(c.y(), c.x()), reach = std::atan2(size.head<2>().norm(), c.head<2>().norm());
  const double floor_z = T_world_box.translation().z() - half.z();
  const double step = 0.17 * M_PI / 180.0;
  const double first = column_phase < 0 ? az_c - reach : (std::floor((az_c - reach) / step) + column_phase) * step;
  ObjectPoints out;
  for (int beam = 0; beam < 64; ++beam) {
    const double el = (2.0 - beam * 26.9 / 63.0) * M_PI / 180.0;
    for (double az = first; az <= az_c + reach; az += step) {
      const Eigen::Vector3d dir(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
      double hit;
      const bool on_box = rayBox(inv * sensor, inv.linear() * dir, half, &hit);
      double ground_hit = dir.z() < -1e-6 ? (floor_z - sensor.z()) / dir.z() : 1e9;
      if (on_box && hit < ground_hit) {
        out.push_back((sensor + (hit + n(rng)) * dir).cast<float>());
      } else if (ground && ground_hit < 1e8) {
        const Eigen::Vector3d g = inv * (sensor + ground_hit * dir);
        if (std::abs(g.x()) < half.x() + ground_margin && std::abs(g.y()) < half.y() + ground_margin)
          out.push_back((sensor + (ground_hit + n(rng)) * dir).cast<float>());
      }
    }
  }
  return out;
}

}  // namespace dlslot::backend::test
