// Strict YAML config: missing, ill-typed and unknown keys are errors naming file and key.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "dlslot/config.hpp"

using namespace dlslot;

namespace {
std::string writeYaml(const std::string& name, const std::string& text) {
  const auto path = (std::filesystem::temp_directory_path() / name).string();
  std::ofstream(path) << text;
  return path;
}
std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(Config, ReadsTypedValuesAndSections) {
  auto root = loadConfig(writeYaml("cfg_ok.yaml", "odometry:\n  margin: 0.5\n  name: x\n  n: 3\n  on: true\n  v: [1, 2]\n"));
  auto s = root.section("odometry");
  EXPECT_DOUBLE_EQ(s.get<double>("margin"), 0.5);
  EXPECT_EQ(s.get<std::string>("name"), "x");
  EXPECT_EQ(s.get<int>("n"), 3);
  EXPECT_TRUE(s.get<bool>("on"));
  EXPECT_EQ(s.get<std::vector<double>>("v").size(), 2u);
  EXPECT_NO_THROW(s.finish());
}

TEST(Config, MissingIllTypedAndUnknownKeysAreErrors) {
  const std::string file = writeYaml("cfg_bad.yaml", "odometry:\n  margin: abc\n  typo_key: 1\n");
  auto s = loadConfig(file).section("odometry");
  const std::string missing = errorOf([&] { s.get<double>("min_range"); });
  EXPECT_NE(missing.find(file + ": odometry.min_range: missing (expected a number)"), std::string::npos) << missing;
  const std::string typed = errorOf([&] { s.get<double>("margin"); });
  EXPECT_NE(typed.find("odometry.margin (line 2): expected a number, got 'abc'"), std::string::npos) << typed;
  const std::string unknown = errorOf([&] { s.finish(); });
  EXPECT_NE(unknown.find("odometry.typo_key (line 3): unknown key"), std::string::npos) << unknown;
}

TEST(Config, MissingFileAndInvalidYaml) {
  EXPECT_NE(errorOf([] { loadConfig("/nonexistent/dlslot.yaml"); }).find("/nonexistent/dlslot.yaml: cannot open"),
            std::string::npos);
  const std::string file = writeYaml("cfg_invalid.yaml", "a: [1, 2\n");
  EXPECT_NE(errorOf([&] { loadConfig(file); }).find("not valid YAML"), std::string::npos);
}

TEST(Config, ShippedConfigHasChannels) {
  auto root = loadConfig(std::string(DLSLOT_SOURCE_DIR) + "/config/dlslot.yaml");
  Channels c;
  EXPECT_NO_THROW(c.read(root.section("channels")));
  EXPECT_EQ(c.scan, "LIDAR_SCAN");
}

TEST(Config, PipelineConfigRejectsAMisspeltSection) {
  const std::string ok = writeYaml("cfg_pipe_ok.yaml",
                                   "channels: {scan: A, detections: B, ground_truth: C, odometry: D, associations: E,"
                                   " slot_state: F, status: G}\ntracker: {}\n");
  Channels c;
  EXPECT_NO_THROW(loadPipelineConfig(ok, c));
  EXPECT_EQ(c.slot_state, "F");
  const std::string bad = writeYaml("cfg_pipe_bad.yaml",
                                    "channels: {scan: A, detections: B, ground_truth: C, odometry: D, associations: E,"
                                    " slot_state: F, status: G}\ntrackr: {}\n");
  const std::string e = errorOf([&] { loadPipelineConfig(bad, c); });
  EXPECT_NE(e.find("trackr (line 2): unknown key"), std::string::npos) << e;
}

TEST(Config, TheDefaultConfigIsFoundFromAnyDirectory) {
  namespace fs = std::filesystem;
  const fs::path before = fs::current_path();
  fs::current_path(fs::temp_directory_path());  // no config/ here
  ::unsetenv("DLSLOT_CONFIG");
  const std::string found = findConfigFile();
  EXPECT_TRUE(fs::is_regular_file(found)) << found;
  EXPECT_EQ(fs::path(found).filename(), "dlslot.yaml");
  // $DLSLOT_CONFIG wins for the default; an explicit path is used as given.
  const std::string mine = writeYaml("cfg_env.yaml", "channels: {}\n");
  ::setenv("DLSLOT_CONFIG", mine.c_str(), 1);
  EXPECT_EQ(findConfigFile(), mine);
  EXPECT_EQ(findConfigFile("elsewhere/x.yaml"), "elsewhere/x.yaml");
  ::unsetenv("DLSLOT_CONFIG");
  EXPECT_NE(errorOf([] { loadConfig("/nonexistent/dlslot.yaml"); }).find("/nonexistent/dlslot.yaml"), std::string::npos);
  fs::current_path(before);
}

// Found by fuzz_file_config: a key that is a map, a list or empty ("? a: b", "? [a]", "?") made
// yaml-cpp throw its own exception out of the unknown-key check, past every ConfigError handler.
TEST(Config, AKeyThatIsNotANameIsAConfigError) {
  Channels channels;
  for (const std::string& text : {std::string("? Every key: y\n"), std::string("? [a, b]\n: 1\n"),
                                  std::string("channels: {}\n?\n: 1\n")}) {
    const std::string path = writeYaml("cfg_key.yaml", text);
    const std::string e = errorOf([&] { loadPipelineConfig(path, channels); });
    EXPECT_NE(e.find(path), std::string::npos) << text << " -> " << e;
    EXPECT_NE(e.find("expected a key name"), std::string::npos) << text << " -> " << e;
  }
}

// Two roles on one channel (channels.odometry: SLOT_STATE) once ran to exit 0 with no DL-SLOT
// trajectory and no tracks: each channel needs a name of its own.
TEST(Config, TwoChannelsWithOneNameAreRefusedNamingBoth) {
  const std::string file = writeYaml("cfg_same_channel.yaml",
                                     "channels: {scan: A, detections: B, ground_truth: C, odometry: F, associations: E,"
                                     " slot_state: F, status: G}\n");
  Channels c;
  const std::string e = errorOf([&] { loadPipelineConfig(file, c); });
  EXPECT_NE(e.find("channels.slot_state: channel 'F' is already channels.odometry"), std::string::npos) << e;
  const std::string run_event = writeYaml("cfg_same_event.yaml",
                                          "channels: {scan: A, detections: B, ground_truth: C, odometry: D, "
                                          "associations: E, slot_state: F, status: G, run_event: A}\n");
  const std::string e2 = errorOf([&] { loadPipelineConfig(run_event, c); });
  EXPECT_NE(e2.find("channels.run_event: channel 'A' is already channels.scan"), std::string::npos) << e2;
}

// .nan parses as a YAML number; no setting means it.
TEST(Config, NanIsRefusedNamingTheKey) {
  for (const std::string v : {".nan", ".NaN"}) {
    const std::string file = writeYaml("cfg_nan.yaml", "odometry:\n  margin: " + v + "\n  list: [1, " + v + "]\n");
    ConfigSection s = loadConfig(file).section("odometry");
    std::string e = errorOf([&] { s.get<double>("margin"); });
    EXPECT_NE(e.find("odometry.margin (line 2): expected a number, got '" + v + "'"), std::string::npos) << e;
    e = errorOf([&] { s.get<std::vector<double>>("list"); });
    EXPECT_NE(e.find("odometry.list (line 3): expected a number, got a list with .nan"), std::string::npos) << e;
  }
}

TEST(Config, TheLidarSectionIsReadOnceForEveryProcess) {
  Channels c;
  ConfigSection root = loadPipelineConfig(std::string(DLSLOT_SOURCE_DIR) + "/config/dlslot.yaml", c);
  const LidarConfig lidar = LidarConfig::read(root.section("lidar"));
  EXPECT_DOUBLE_EQ(lidar.sweep.period_s, 0.1);
  EXPECT_TRUE(lidar.sweep.clockwise);
  EXPECT_NEAR(lidar.vertical_angle_error_rad, 0.22 * M_PI / 180.0, 1e-12);
  // A value out of range, and a key that belongs elsewhere, are errors naming the file and the key.
  const std::string bad = writeYaml("cfg_lidar.yaml", "lidar:\n  sweep_period_s: 2\n  sweep_clockwise: true\n  vertical_angle_error_deg: 0\n");
  const std::string e = errorOf([&] { LidarConfig::read(loadConfig(bad).section("lidar")); });
  EXPECT_NE(e.find("cfg_lidar.yaml: lidar.sweep_period_s: expected a value in [0, 1] s"), std::string::npos) << e;
  const std::string extra = writeYaml("cfg_lidar2.yaml",
                                      "lidar:\n  sweep_period_s: 0\n  sweep_clockwise: true\n  vertical_angle_error_deg: 0\n  min_range_m: 2\n");
  EXPECT_NE(errorOf([&] { LidarConfig::read(loadConfig(extra).section("lidar")); }).find("min_range_m"), std::string::npos);
}
