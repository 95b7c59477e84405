// The incrementally updated local map (local_map.hpp, block_index.hpp): nearest-neighbour
// queries against a brute-force search over the same voxel means, cropping against a
// brute-force filter, the running mean per voxel, the block hash against std::unordered_map, and
// the scan's voxel downsampling against PCL's VoxelGrid filter.
#include <gtest/gtest.h>
#include <pcl/filters/voxel_grid.h>

#include <algorithm>
#include <random>
#include <unordered_map>

#include "odometry/local_map.hpp"
#include "odometry/scan_to_map.hpp"
#include "odometry_random_cloud.hpp"

namespace dlslot::odometry {
namespace {

// The k nearest of `all` within radius, nearest first.
std::vector<float> bruteForce(const std::vector<Eigen::Vector3f>& all, const Eigen::Vector3f& q, int k, float radius) {
  std::vector<float> d2;
  for (const auto& p : all)
    if ((p - q).squaredNorm() < radius * radius) d2.push_back((p - q).squaredNorm());
  std::sort(d2.begin(), d2.end());
  if (static_cast<int>(d2.size()) > k) d2.resize(k);
  return d2;
}

TEST(OdometryLocalMap, NearestAgreesWithBruteForce) {
  std::mt19937 rng(7);
  for (const auto& [voxel, radius] : {std::pair{0.4, 1.0}, std::pair{0.8, 1.0}, std::pair{0.3, 0.5}}) {
    VoxelLayer layer(voxel, radius);
    for (int scan = 0; scan < 3; ++scan) {
      Eigen::Isometry3f T = Eigen::Isometry3f::Identity();
      T.translation() = Eigen::Vector3f(0.7f * scan, -0.3f * scan, 0.0f);
      T.linear() = Eigen::AngleAxisf(0.2f * scan, Eigen::Vector3f::UnitZ()).toRotationMatrix();
      layer.insert(test::randomFlatCloud(4000, 12.0f, 0.1f, rng), T);
    }
    const std::vector<Eigen::Vector3f> all = layer.points();
    ASSERT_EQ(all.size(), layer.size());
    std::uniform_real_distribution<float> U(-14.0f, 14.0f);
    Neighbours nb;
    int full = 0;
    for (int i = 0; i < 500; ++i) {
      const Eigen::Vector3f q(U(rng), U(rng), 0.3f * U(rng) / 14.0f);
      const std::vector<float> expected = bruteForce(all, q, 5, static_cast<float>(radius));
      layer.nearest(q, 5, nb);
      ASSERT_EQ(nb.size(), static_cast<int>(expected.size())) << "query " << i;
      for (int j = 0; j < nb.size(); ++j) {
        EXPECT_FLOAT_EQ(nb.d2[j], expected[j]);
        EXPECT_FLOAT_EQ((nb.points[j] - q).squaredNorm(), nb.d2[j]);
      }
      full += nb.size() == 5;
    }
    EXPECT_GT(full, 100) << "the queries must also exercise full neighbourhoods";
  }
}

TEST(OdometryLocalMap, RunningMeanPerVoxel) {
  VoxelLayer layer(1.0, 1.0);
  FeatureCloud c;
  for (float x : {0.1f, 0.3f, 0.8f, 1.2f}) {  // three in voxel [0,1), one in [1,2)
    pcl::PointXYZI p;
    p.x = x;
    p.y = p.z = 0.5f;
    c.push_back(p);
  }
  layer.insert(c, Eigen::Isometry3f::Identity());
  std::vector<Eigen::Vector3f> pts = layer.points();
  ASSERT_EQ(pts.size(), 2u);
  std::sort(pts.begin(), pts.end(), [](const auto& a, const auto& b) { return a.x() < b.x(); });
  EXPECT_NEAR(pts[0].x(), 0.4f, 1e-6);
  EXPECT_NEAR(pts[1].x(), 1.2f, 1e-6);
}

TEST(OdometryLocalMap, CropKeepsExactlyThePointsWithinTheRadius) {
  std::mt19937 rng(11);
  VoxelLayer layer(0.4, 1.0);
  layer.insert(test::randomFlatCloud(20000, 60.0f, 0.1f, rng), Eigen::Isometry3f::Identity());
  const std::vector<Eigen::Vector3f> before = layer.points();
  const Eigen::Vector3d center(13.3, -7.1, 2.0);
  const double radius = 31.7;
  layer.crop(center, radius);
  std::vector<Eigen::Vector3f> expected;
  for (const auto& p : before)
    if ((p.head<2>() - center.head<2>().cast<float>()).squaredNorm() <= static_cast<float>(radius * radius))
      expected.push_back(p);
  std::vector<Eigen::Vector3f> after = layer.points();
  ASSERT_EQ(after.size(), expected.size());
  ASSERT_EQ(layer.size(), expected.size());
  auto less = [](const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
    return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
  };
  std::sort(after.begin(), after.end(), less);
  std::sort(expected.begin(), expected.end(), less);
  EXPECT_EQ(after, expected);
  // Queries still find what is left (the hash survived the block removals).
  Neighbours nb;
  for (size_t i = 0; i < expected.size(); i += 97) {
    layer.nearest(expected[i], 1, nb);
    ASSERT_EQ(nb.size(), 1);
    EXPECT_EQ(nb.d2[0], 0.0f);
  }
  layer.clear();
  EXPECT_EQ(layer.size(), 0u);
  layer.nearest(expected[0], 1, nb);
  EXPECT_EQ(nb.size(), 0);
}

TEST(OdometryBlockIndex, AgreesWithAnUnorderedMap) {
  std::mt19937 rng(3);
  std::uniform_int_distribution<int64_t> key(-3000, 3000);
  BlockIndex index;
  std::unordered_map<int64_t, int> reference;
  for (int i = 0; i < 200000; ++i) {
    const int64_t k = key(rng);
    if (rng() % 3 == 0) {
      index.erase(k);
      reference.erase(k);
    } else {
      index.set(k, i);
      reference[k] = i;
    }
  }
  EXPECT_EQ(index.size(), reference.size());
  for (int64_t k = -3000; k <= 3000; ++k) {
    const auto it = reference.find(k);
    EXPECT_EQ(index.find(k), it == reference.end() ? BlockIndex::kMissing : it->second) << "key " << k;
  }
}

// The same voxels, in the same order, with the same centroids (to float rounding: the sums may
// run in another order) as PCL's VoxelGrid, which it replaces; no NaN passes.
TEST(OdometryDownsample, EqualsPclVoxelGrid) {
  std::mt19937 rng(7);
  FeatureCloud cloud = test::randomFlatCloud(20000, 40.0f, 0.1f, rng);
  cloud[5].x = std::numeric_limits<float>::quiet_NaN();
  cloud.is_dense = false;  // PCL checks for NaN only then
  for (const double voxel : {0.4, 0.8}) {
    FeatureCloud expected;
    pcl::VoxelGrid<pcl::PointXYZI> grid;
    const float v = static_cast<float>(voxel);
    grid.setLeafSize(v, v, v);
    grid.setInputCloud(FeatureCloud::ConstPtr(&cloud, [](const FeatureCloud*) {}));
    grid.filter(expected);
    const FeatureCloud got = downsample(cloud, voxel);
    ASSERT_EQ(got.size(), expected.size()) << voxel;
    ASSERT_LT(got.size(), cloud.size());
    for (size_t i = 0; i < got.size(); ++i) {
      ASSERT_LT((got[i].getVector3fMap() - expected[i].getVector3fMap()).norm(), 1e-4f) << voxel << " point " << i;
      ASSERT_NEAR(got[i].intensity, expected[i].intensity, 1e-3f);
    }
  }
  EXPECT_TRUE(downsample(FeatureCloud(), 0.4).empty());
}

// Only near-vertical lines are matched as edges (scan_to_map.edge_max_tilt_deg): a ring crosses a
// horizontal corner (a wall's foot, a kerb) where its cone meets it, which moves with the viewpoint.
TEST(OdometryScanToMap, HorizontalLinesAreNotMatchedAsEdgesBeyondTheTiltLimit) {
  FeatureCloud pole, foot;
  for (int i = 0; i < 40; ++i) {
    pole.push_back(pcl::PointXYZI(5.0f, 2.0f, -1.5f + 0.1f * i, 0.0f));  // vertical
    foot.push_back(pcl::PointXYZI(-8.0f + 0.1f * i, -4.0f, -1.7f, 0.0f));  // horizontal, along x
  }
  FeatureCloud both = pole;
  both += foot;
  ScanToMapConfig cfg;
  FeatureCloud queries;
  queries.push_back(pcl::PointXYZI(5.05f, 2.0f, 0.0f, 0.0f));
  queries.push_back(pcl::PointXYZI(-6.0f, -4.05f, -1.7f, 0.0f));
  cfg.max_neighbor_distance_m = 2.0;  // five 0.4 m voxel means of a line within reach
  LocalMap map(cfg);
  map.insert(both, FeatureCloud(), Pose::Identity());
  EXPECT_EQ(matchScanToMap(queries, FeatureCloud(), map, Pose::Identity(), cfg).edges.size(), 2u);  // A-LOAM: 90 deg
  cfg.edge_max_tilt_deg = 45.0;
  const Matches m = matchScanToMap(queries, FeatureCloud(), map, Pose::Identity(), cfg);
  ASSERT_EQ(m.edges.size(), 1u);
  EXPECT_NEAR(std::abs(m.edges[0].u.z()), 1.0, 1e-6);
}

}  // namespace
}  // namespace dlslot::odometry
