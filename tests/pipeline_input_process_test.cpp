// Your own data through the whole pipeline: a simulated 32-beam sensor written as a folder of
// .pcd scans with times.txt, the vehicle's poses and a YAML calibration, run by dlslot-run
// --input (inside a private network namespace, see tests/CMakeLists.txt).
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>

#include "dlslot/slot_state_t.hpp"
#include "process_harness.hpp"

using namespace dlslot;
using namespace dlslot::test;
namespace fs = std::filesystem;

namespace {

constexpr int kFrames = 20;

const std::string& simulated32() {
  static const std::string root = [] {
    const std::string dir = binDir() + "/../test-scratch/pipeline-input-32";
    fs::remove_all(dir);
    ChildProcess sim({bin("dlslot-sim"), "--scenario", "intersection", "--frames", std::to_string(kFrames), "--seed",
                      "3", "--beams", "32", "--pcd", "--out", dir},
                     binDir() + "/../test-scratch/pipeline-input-sim.log");
    EXPECT_EQ(sim.wait(300), 0) << sim.output();
    return dir;
  }();
  return root;
}

TEST(PipelineInput, A32BeamPcdFolderRunsThroughTheWholePipeline) {
  const std::string data = simulated32(), out = scratchDir();
  ASSERT_TRUE(fs::exists(data + "/pcd/000000.pcd"));
  ASSERT_TRUE(fs::exists(data + "/pcd/times.txt"));
  ChildProcess run({bin("dlslot-run"), "--config", config(), "--input", data + "/pcd", "--calib",
                    data + "/pcd/calib.yaml", "--detections", data + "/detections/sim/0000.txt", "--no-render",
                    "--quiet", "--out", out},
                   out + "/../pipeline-input-run.log");
  ASSERT_EQ(run.wait(600), 0) << run.output();
  // The run's config carries the sensor's beams for the odometry.
  const YAML::Node cfg = YAML::LoadFile(out + "/config.yaml");
  EXPECT_EQ(cfg["odometry"]["features"]["beam_model"].as<std::string>(), "uniform");
  EXPECT_EQ(cfg["odometry"]["features"]["num_beams"].as<int>(), 32);
  EXPECT_NEAR(cfg["odometry"]["features"]["max_vertical_deg"].as<double>(), 10.67, 1e-9);
  const auto events = readLog(out + "/run.lcmlog");
  const auto states = decodeAll<slot_state_t>(events.at("SLOT_STATE"));
  ASSERT_EQ(states.size(), static_cast<size_t>(kFrames));
  EXPECT_GT(states.back().num_tracks, 0);  // the detections (camera coordinates, camera_calib) were tracked
  // Ground truth from poses.txt through the extrinsics: the ego metrics are against it (a folder
  // has no labelled boxes, so no tracking metrics).
  const YAML::Node m = YAML::LoadFile(out + "/metrics.json");
  EXPECT_LT(m["ego.ate_rmse_m"].as<double>(), 0.5);
}

TEST(PipelineInput, ABadCalibrationIsRefusedNamingTheFileAndKey) {
  const std::string data = simulated32(), out = scratchDir();
  const std::string calib = out + "/calib.yaml";
  std::ofstream(calib) << "sensor_to_vehicle: {translation: [0, 0, 1.73], rotation_rpy_deg: [0, 0, 0]}\n"
                          "beams: {model: uniform, count: 32}\nrange_m: [2.5, 120]\n";
  ChildProcess run({bin("dlslot-run"), "--config", config(), "--input", data + "/pcd", "--calib", calib, "--no-render",
                    "--quiet", "--out", out + "/run"},
                   out + "/run.log");
  EXPECT_NE(run.wait(60), 0);
  EXPECT_NE(run.output().find(calib), std::string::npos) << run.output();
  EXPECT_NE(run.output().find("elevation_deg"), std::string::npos) << run.output();
}

// A simulated lidar without KITTI's vertical-angle error, its scans written de-skewed: the run
// corrects for neither (the shipped config's lidar section is KITTI's: 0.22 deg, a 0.1 s sweep),
// and says so in its config.yaml.
TEST(PipelineInput, AScenarioRunTakesItsLidarFromTheSimulator) {
  const std::string out = scratchDir(), scenario = out + "/plain-lidar.yaml";
  std::ofstream(scenario) << readText(sourceDir() + "/config/scenarios/intersection.yaml")
                          << "\nsensor:\n  vertical_angle_error_deg: 0\n  deskewed: true\n";
  ChildProcess run({bin("dlslot-run"), "--config", config(), "--scenario", scenario, "--frames", "5", "--seed", "2",
                    "--no-render", "--no-map", "--no-eval", "--quiet", "--out", out + "/run"},
                   out + "/run.log");
  ASSERT_EQ(run.wait(300), 0) << run.output();
  const YAML::Node shipped = YAML::LoadFile(config())["lidar"];
  EXPECT_NEAR(shipped["vertical_angle_error_deg"].as<double>(), 0.22, 1e-12);
  EXPECT_GT(shipped["sweep_period_s"].as<double>(), 0.0);
  const YAML::Node lidar = YAML::LoadFile(out + "/run/config.yaml")["lidar"];
  EXPECT_EQ(lidar["vertical_angle_error_deg"].as<double>(), 0.0);
  EXPECT_EQ(lidar["sweep_period_s"].as<double>(), 0.0);
  // The rest of the config is the one given.
  EXPECT_EQ(YAML::LoadFile(out + "/run/config.yaml")["backend"]["window_size"].as<int>(),
            YAML::LoadFile(config())["backend"]["window_size"].as<int>());
}

}  // namespace
