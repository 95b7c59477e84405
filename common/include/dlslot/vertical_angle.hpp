// KITTI's vertical-angle error: the HDL-64E of the KITTI recordings stores each point about 0.22 deg
// below the ray that measured it (its intrinsic calibration; IMLS-SLAM and CT-ICP correct the
// raw scans by it, and the simulator reproduces it: config/scenarios/README.md).
//
// Why it matters: a point at range r is stored r x 0.0038 too low, so the ground seen from one
// place is a shallow cone. Two scans taken tens of metres apart see the same ground at different
// ranges: registered, the cones fit best tilted towards each other, by about the error itself
// (0.2-0.4 deg), and over a loop's ~38 m that is 0.15-0.3 m in height at the far end. Between
// consecutive scans the same tilt, a few thousandths of a degree, adds up: the odometry lost 8 m
// of height over 490 m of flat simulated road before it put its features back on their rays.
#pragma once

#include <cmath>

#include "dlslot/types.hpp"

namespace dlslot {

// Raises a point's elevation (seen from the lidar's origin) by the angle of cosine `c` and sine
// `s`, keeping its range and azimuth: the stored point moved back onto its ray.
inline void raiseElevation(float& x, float& y, float& z, float c, float s) {
  const float rho = std::sqrt(x * x + y * y);
  if (rho <= 0) return;  // straight up or down: no azimuth to keep, no lidar fires there
  const float rho2 = rho * c - z * s;
  z = rho * s + z * c;
  x *= rho2 / rho;
  y *= rho2 / rho;
}

// Every point of `points` moved back onto its ray (raiseElevation by `angle_rad`); 0 leaves them.
inline void correctElevation(PointCloud& points, double angle_rad) {
  if (angle_rad == 0) return;
  const float c = static_cast<float>(std::cos(angle_rad)), s = static_cast<float>(std::sin(angle_rad));
  for (Eigen::Index i = 0; i < points.cols(); ++i) raiseElevation(points(0, i), points(1, i), points(2, i), c, s);
}

}  // namespace dlslot
