// The odometry section of the shipped config, and config errors that name the key.
#include <gtest/gtest.h>

#include <fstream>

#include "odometry/odometry_config.hpp"

namespace dlslot::odometry {
namespace {

std::string shippedConfig() { return std::string(DLSLOT_SOURCE_DIR) + "/config/dlslot.yaml"; }

TEST(OdometryConfig, ShippedSectionIsCompleteAndMatchesTheDefaults) {
  ConfigSection root = loadConfig(shippedConfig());
  ConfigSection s = root.section("odometry");
  const OdometryConfig c = readOdometryConfig(s);
  EXPECT_GT(s.get<double>("detections_timeout_s"), 0.0);
  EXPECT_NO_THROW(s.finish());
  const OdometryConfig d;
  EXPECT_EQ(c.remove_detected_objects, d.remove_detected_objects);
  EXPECT_DOUBLE_EQ(c.box_margin_m, d.box_margin_m);
  EXPECT_DOUBLE_EQ(c.ground_clearance_m, d.ground_clearance_m);
  EXPECT_EQ(c.features.beam_model, d.features.beam_model);
  EXPECT_EQ(c.scan_to_scan.every_scan, d.scan_to_scan.every_scan);
  EXPECT_EQ(c.features.less_sharp_per_sector, d.features.less_sharp_per_sector);
  EXPECT_DOUBLE_EQ(c.scan_to_map.plane_voxel_m, d.scan_to_map.plane_voxel_m);
  EXPECT_EQ(c.scan_to_map.solver.outer_iterations, d.scan_to_map.solver.outer_iterations);
  EXPECT_DOUBLE_EQ(c.scan_to_map.solver.converged_step_m, d.scan_to_map.solver.converged_step_m);
  EXPECT_DOUBLE_EQ(c.scan_to_map.solver.converged_step_deg, d.scan_to_map.solver.converged_step_deg);
}

std::string withReplaced(const std::string& from, const std::string& to) {
  std::ifstream in(shippedConfig());
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  text.replace(at, from.size(), to);
  const std::string path = testing::TempDir() + "/odometry_config_test.yaml";
  std::ofstream(path) << text;
  return path;
}

std::string errorOf(const std::string& path) {
  try {
    ConfigSection root = loadConfig(path);
    ConfigSection s = root.section("odometry");
    readOdometryConfig(s);
    s.skip("detections_timeout_s");
    s.finish();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(OdometryConfig, ErrorsNameTheKey) {
  EXPECT_NE(errorOf(withReplaced("mode: aloam-filtered", "mode: loam")).find("odometry.mode"), std::string::npos);
  EXPECT_NE(errorOf(withReplaced("beam_model: hdl64", "beam_model: vlp16")).find("beam_model"), std::string::npos);
  EXPECT_NE(errorOf(withReplaced("min_range_m: 5.0", "min_range_mm: 5.0")).find("min_range_m"), std::string::npos);
  EXPECT_NE(errorOf(withReplaced("neighbors: 5", "neighbors: 2")).find("neighbors"), std::string::npos);
  EXPECT_NE(errorOf(withReplaced("box_margin_m: 0.3", "box_margin_m: -0.3")).find("box_margin_m"), std::string::npos);
  EXPECT_NE(errorOf(withReplaced("ground_clearance_m: 0.25", "ground_clearance_m: .nan")).find("ground_clearance_m"),
            std::string::npos);
}

TEST(OdometryConfig, ModeNames) {
  EXPECT_FALSE(removesDetectedObjects("aloam"));
  EXPECT_TRUE(removesDetectedObjects("aloam-filtered"));
  EXPECT_THROW(removesDetectedObjects("slot"), std::invalid_argument);
  EXPECT_STREQ(modeName(true), "aloam-filtered");
  EXPECT_STREQ(modeName(false), "aloam");
}

}  // namespace
}  // namespace dlslot::odometry
