// KITTI's vertical-angle error corrected with a known answer: flat ground seen through rays that
// leave above their stored points' elevation is a cone as stored and flat again once corrected.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "dlslot/vertical_angle.hpp"

using namespace dlslot;

TEST(VerticalAngle, FlatGroundSeenThroughRaysAboveTheirStoredPointsIsFlatAgain) {
  // Rays leave 0.22 deg above the elevation their points are stored with (KITTI's HDL-64E): the
  // ground 1.73 m below the lidar is stored as a cone sinking r x 0.0038 m with range r.
  const double h = 1.73, err = 0.22 * M_PI / 180.0;
  PointCloud scan(4, 0);
  std::vector<double> ranges;
  for (double e_deg = -24.0; e_deg <= -2.0; e_deg += 0.5)
    for (int a = 0; a < 36; ++a) {
      const double e = e_deg * M_PI / 180.0, az = a * 10.0 * M_PI / 180.0;
      const double s = h / std::sin(-(e + err));  // the true ray hits the ground
      if (s > 60) continue;
      scan.conservativeResize(4, scan.cols() + 1);
      scan.col(scan.cols() - 1) << static_cast<float>(s * std::cos(e) * std::cos(az)),
          static_cast<float>(s * std::cos(e) * std::sin(az)), static_cast<float>(s * std::sin(e)), 0.2f;
    }
  ASSERT_GT(scan.cols(), 500);
  const auto worst = [&](const PointCloud& p) { return (p.row(2).array() + static_cast<float>(h)).abs().maxCoeff(); };
  EXPECT_GT(worst(scan), 0.15f);  // ~45 m away: 0.17 m too low
  PointCloud corrected = scan;
  correctElevation(corrected, err);
  EXPECT_LT(worst(corrected), 2e-4f);
  // Range and azimuth are kept; 0 leaves the points.
  for (Eigen::Index i = 0; i < scan.cols(); ++i) {
    EXPECT_NEAR(corrected.col(i).head<3>().norm(), scan.col(i).head<3>().norm(), 1e-4f);
    EXPECT_NEAR(std::atan2(corrected(1, i), corrected(0, i)), std::atan2(scan(1, i), scan(0, i)), 1e-5);
  }
  PointCloud same = scan;
  correctElevation(same, 0.0);
  EXPECT_EQ((same - scan).cwiseAbs().maxCoeff(), 0.0f);
}
