// Feature extraction (paper III-D, A-LOAM scanRegistration): beam index, curvature, edge and
// plane selection on constructed scans with known geometry.
#include <gtest/gtest.h>

#include <random>

#include <cmath>
#include <limits>
#include <map>

#include "odometry/beam_index.hpp"
#include "odometry/curvature.hpp"
#include "odometry/feature_extraction.hpp"
#include "odometry_scene.hpp"

namespace dlslot::odometry {
namespace {

Eigen::Vector3f atElevation(double elev_deg, double range = 20.0, double az_deg = 30.0) {
  const double el = elev_deg * M_PI / 180.0, az = az_deg * M_PI / 180.0;
  return Eigen::Vector3d(range * std::cos(el) * std::cos(az), range * std::cos(el) * std::sin(az),
                         range * std::sin(el))
      .cast<float>();
}

TEST(OdometryBeamIndex, Hdl64RuleOfALoam) {
  const BeamModel model{FeatureConfig()};
  EXPECT_EQ(model.beamOf(atElevation(2.0)), 0);
  EXPECT_EQ(model.beamOf(atElevation(-8.33)), 31);
  EXPECT_EQ(model.beamOf(atElevation(-8.83)), 32);
  EXPECT_EQ(model.beamOf(atElevation(-17.33)), 49);
  EXPECT_EQ(model.beamOf(atElevation(2.5)), -1);     // above the top beam
  EXPECT_EQ(model.beamOf(atElevation(-20.0)), -1);   // A-LOAM uses beams 0..50 only
  // Every HDL-64E elevation down to beam 50 gets its own index, in order.
  const std::vector<double> elev = test::hdl64ElevationsDeg();
  for (int b = 1; b <= 50; ++b) EXPECT_EQ(model.beamOf(atElevation(elev[b])), b) << "beam " << b;
}

TEST(OdometryBeamIndex, TableLookupEqualsTheAngleRule) {
  FeatureConfig uniform;
  uniform.beam_model = "uniform";
  uniform.num_beams = 32;
  for (const FeatureConfig& cfg : {FeatureConfig(), uniform}) {
    const BeamModel model(cfg);
    std::mt19937 rng(9);
    std::uniform_real_distribution<float> U(-1.0f, 1.0f);
    for (int i = 0; i < 200000; ++i) {
      const Eigen::Vector3f p(60.0f * U(rng), 60.0f * U(rng), 8.0f * U(rng));
      const float angle = std::atan2(p.z(), std::sqrt(p.x() * p.x() + p.y() * p.y())) * static_cast<float>(180.0 / M_PI);
      ASSERT_EQ(model.beamOf(p), model.beamOfAngle(angle)) << cfg.beam_model << " at " << angle << " deg";
    }
  }
}

TEST(OdometryBeamIndex, UniformModelFromConfig) {
  FeatureConfig cfg;
  cfg.beam_model = "uniform";
  cfg.num_beams = 16;
  cfg.min_vertical_deg = -15.0;
  cfg.max_vertical_deg = 15.0;
  const BeamModel model(cfg);
  EXPECT_EQ(model.numBeams(), 16);
  EXPECT_EQ(model.beamOf(atElevation(15.0)), 0);
  EXPECT_EQ(model.beamOf(atElevation(-15.0)), 15);
  EXPECT_EQ(model.beamOf(atElevation(1.0)), 7);
  EXPECT_EQ(model.beamOf(atElevation(17.0)), -1);
}

TEST(OdometryCurvature, ZeroOnALineKnownOnABump) {
  const int n = 40, w = 5, bump = 20;
  const double delta = 0.05;
  Eigen::Matrix3Xf ring(3, n);
  for (int i = 0; i < n; ++i) ring.col(i) = Eigen::Vector3f(0.1f * i, 10.0f, 0.0f);
  ring(1, bump) += static_cast<float>(delta);  // one point pushed off the line
  const Eigen::VectorXf c = ringCurvature(ring, w);
  for (int i = 0; i < w; ++i) {
    EXPECT_EQ(c[i], -1.0f);
    EXPECT_EQ(c[n - 1 - i], -1.0f);
  }
  // sum_j (p_j - p_i) over the 10 neighbours: -10 delta at the bump, +delta within its window.
  EXPECT_NEAR(c[bump], 100 * delta * delta, 1e-5);
  for (int k = 1; k <= w; ++k) {
    EXPECT_NEAR(c[bump - k], delta * delta, 1e-5);
    EXPECT_NEAR(c[bump + k], delta * delta, 1e-5);
  }
  EXPECT_NEAR(c[bump + w + 1], 0.0, 1e-6);
  EXPECT_NEAR(c[w], 0.0, 1e-6);
}

TEST(OdometryFeatures, APlaneYieldsOnlyPlaneFeatures) {
  test::Scene ground;
  ground.ground_z = -1.73;
  const ScanFeatures f = extractFeatures(ground.scan(Pose::Identity()), FeatureConfig());
  EXPECT_GT(f.num_points, 20000);
  EXPECT_TRUE(f.sharp.empty());
  EXPECT_TRUE(f.less_sharp.empty());
  EXPECT_GT(f.flat.size(), 100u);
  EXPECT_GT(f.less_flat.size(), f.flat.size());
  for (const auto& p : f.flat) EXPECT_NEAR(p.z, -1.73, 1e-3);
}

TEST(OdometryFeatures, TwoWallsMeetingYieldEdgesAlongTheCorner) {
  // Walls x = 10 (y in [-5, 8]) and y = 8 (x in [-3, 10]) meet in the vertical line (10, 8).
  test::Scene corner;
  corner.rects.push_back(test::wall({10, -5}, {10, 8}, -3, 6));
  corner.rects.push_back(test::wall({-3, 8}, {10, 8}, -3, 6));
  const ScanFeatures f = extractFeatures(corner.scan(Pose::Identity()), FeatureConfig());
  ASSERT_FALSE(f.sharp.empty());
  std::map<int, int> edges_per_beam;
  for (const auto& p : f.less_sharp) {
    EXPECT_LT(std::hypot(p.x - 10.0, p.y - 8.0), 0.25) << "edge feature off the corner at " << p.x << " " << p.y;
    ++edges_per_beam[static_cast<int>(p.intensity)];
  }
  // The corner is seen by every beam whose ray reaches it; suppression leaves one edge per beam.
  EXPECT_GT(edges_per_beam.size(), 30u);
  for (const auto& [beam, n] : edges_per_beam) EXPECT_EQ(n, 1) << "beam " << beam;
  for (const auto& p : f.flat) EXPECT_GT(std::hypot(p.x - 10.0, p.y - 8.0), 0.3);
  EXPECT_GT(f.flat.size(), 100u);
}

TEST(OdometryFeatures, FeaturesAreOrderedByBeam) {
  const ScanFeatures f = extractFeatures(test::street().scan(Pose::Identity()), FeatureConfig());
  for (const FeatureCloud* c : {&f.sharp, &f.less_sharp, &f.flat, &f.less_flat}) {
    ASSERT_FALSE(c->empty());
    for (size_t i = 1; i < c->size(); ++i) EXPECT_LE((*c)[i - 1].intensity, (*c)[i].intensity);
  }
  const FeatureConfig cfg;
  const int beams_used = 51;
  EXPECT_LE(f.sharp.size(), static_cast<size_t>(beams_used * cfg.sectors_per_beam * cfg.sharp_per_sector));
  EXPECT_LE(f.less_sharp.size(), static_cast<size_t>(beams_used * cfg.sectors_per_beam * cfg.less_sharp_per_sector));
  EXPECT_LE(f.flat.size(), static_cast<size_t>(beams_used * cfg.sectors_per_beam * cfg.flat_per_sector));
}

TEST(OdometryFeatures, PointsCloserThanTheMinimumRangeAreIgnored) {
  test::Scene close;  // a 6 m x 6 m room: every wall point within 3 * sqrt(2) < min_range_m
  close.rects = {test::wall({3, -3}, {3, 3}, -5, 5), test::wall({3, 3}, {-3, 3}, -5, 5),
                 test::wall({-3, 3}, {-3, -3}, -5, 5), test::wall({-3, -3}, {3, -3}, -5, 5)};
  const ScanFeatures f = extractFeatures(close.scan(Pose::Identity()), FeatureConfig());
  EXPECT_GT(close.scan(Pose::Identity()).cols(), 1000);
  EXPECT_EQ(f.num_points, 0);
  EXPECT_TRUE(f.less_flat.empty());
}

TEST(OdometryFeatures, DegenerateScansGiveNoFeatures) {
  const FeatureConfig cfg;
  const ScanFeatures empty = extractFeatures(PointCloud(4, 0), cfg);
  EXPECT_EQ(empty.num_points, 0);
  EXPECT_TRUE(empty.sharp.empty() && empty.less_sharp.empty() && empty.flat.empty() && empty.less_flat.empty());

  const PointCloud nan = PointCloud::Constant(4, 5000, std::numeric_limits<float>::quiet_NaN());
  const ScanFeatures from_nan = extractFeatures(nan, cfg);
  EXPECT_EQ(from_nan.num_points, 0);
  EXPECT_TRUE(from_nan.less_flat.empty());

  PointCloud inf = PointCloud::Constant(4, 100, std::numeric_limits<float>::infinity());
  EXPECT_EQ(extractFeatures(inf, cfg).num_points, 0);
}

}  // namespace
}  // namespace dlslot::odometry
