// Random feature clouds for the odometry's neighbour-search tests: points spread over a square of
// side 2 * extent, flattened in z by `z_fraction` (like a street: many points share cells).
#pragma once

#include <random>

#include "odometry/feature_extraction.hpp"

namespace dlslot::odometry::test {

inline FeatureCloud randomFlatCloud(int n, float extent, float z_fraction, std::mt19937& rng) {
  std::uniform_real_distribution<float> U(-extent, extent);
  FeatureCloud c;
  for (int i = 0; i < n; ++i) {
    pcl::PointXYZI p;
    p.x = U(rng);
    p.y = U(rng);
    p.z = z_fraction * U(rng);
    p.intensity = static_cast<float>(i % 64);
    c.push_back(p);
  }
  return c;
}

}  // namespace dlslot::odometry::test
