// The scan-to-scan neighbour grid (point_grid.hpp) against a brute-force k-nearest search, on
// dense and sparse clouds, with queries near and far from any point.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "odometry/point_grid.hpp"
#include "odometry_random_cloud.hpp"

namespace dlslot::odometry {
namespace {

TEST(OdometryPointGrid, NearestAgreesWithBruteForce) {
  std::mt19937 rng(17);
  for (const auto& [cell, n, extent] : {std::tuple{0.5, 20000, 30.0f}, std::tuple{1.0, 800, 40.0f}, std::tuple{0.3, 50, 10.0f}}) {
    const FeatureCloud cloud = test::randomFlatCloud(n, extent, 0.2f, rng);
    PointGrid grid(cell);
    grid.build(cloud);
    std::uniform_real_distribution<float> U(-extent - 3.0f, extent + 3.0f);
    std::vector<int> idx;
    std::vector<float> d2;
    for (int q = 0; q < 300; ++q) {
      const Eigen::Vector3f p(U(rng), U(rng), U(rng) * 0.1f);
      const float max_d2 = 25.0f;
      std::vector<std::pair<float, int>> all;
      for (int i = 0; i < n; ++i) {
        const float d = (cloud[i].getVector3fMap() - p).squaredNorm();
        if (d < max_d2) all.push_back({d, i});
      }
      std::sort(all.begin(), all.end());
      if (all.size() > 10) all.resize(10);
      grid.nearest(p, 10, max_d2, idx, d2);
      ASSERT_EQ(idx.size(), all.size()) << "cell " << cell << " query " << q;
      for (size_t j = 0; j < all.size(); ++j) {
        EXPECT_FLOAT_EQ(d2[j], all[j].first);
        EXPECT_FLOAT_EQ((cloud[idx[j]].getVector3fMap() - p).squaredNorm(), d2[j]);
      }
    }
  }
}

TEST(OdometryPointGrid, EmptyAndRebuilt) {
  PointGrid grid(0.5);
  std::vector<int> idx;
  std::vector<float> d2;
  grid.build(FeatureCloud());
  EXPECT_TRUE(grid.empty());
  grid.nearest(Eigen::Vector3f::Zero(), 5, 25.0f, idx, d2);
  EXPECT_TRUE(idx.empty());
  std::mt19937 rng(1);
  const FeatureCloud a = test::randomFlatCloud(100, 5.0f, 0.2f, rng), b = test::randomFlatCloud(3, 5.0f, 0.2f, rng);
  grid.build(a);
  grid.build(b);  // nothing of a is left
  grid.nearest(Eigen::Vector3f::Zero(), 10, 1e6f, idx, d2);
  EXPECT_EQ(idx.size(), 3u);
}

}  // namespace
}  // namespace dlslot::odometry
