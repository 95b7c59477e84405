// dlslot-sim writes what it simulated: the same seed gives the same bytes, and the KITTI files
// read back through kitti::SequenceReader (the player's reader) give the generated ground truth.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>

#include "dlslot/kitti.hpp"
#include "sim/oxts.hpp"
#include "sim/sim.hpp"
#include "sim/simulation.hpp"
#include "sim_scenario.hpp"

namespace fs = std::filesystem;
using namespace dlslot;

namespace {

fs::path tempDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("dlslot_sim_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir;
}

// FNV-1a over every file's relative path and bytes, in path order.
uint64_t hashTree(const fs::path& root, std::map<std::string, uint64_t>* per_file = nullptr) {
  std::vector<fs::path> files;
  for (const auto& e : fs::recursive_directory_iterator(root))
    if (e.is_regular_file()) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  uint64_t h = 1469598103934665603ULL;
  auto feed = [&h](const char* p, size_t n) {
    for (size_t i = 0; i < n; ++i) h = (h ^ static_cast<unsigned char>(p[i])) * 1099511628211ULL;
  };
  for (const fs::path& f : files) {
    const std::string rel = fs::relative(f, root).string();
    feed(rel.data(), rel.size());
    std::ifstream in(f, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const uint64_t before = h;
    feed(bytes.data(), bytes.size());
    if (per_file) (*per_file)[rel] = h ^ before;
  }
  return h;
}

}  // namespace

TEST(SimSequence, SameSeedSameBytesOtherSeedOtherBytes) {
  const sim::Scenario sc = sim::test::shippedScenario("intersection", 4);
  const fs::path a = tempDir("det_a"), b = tempDir("det_b"), c = tempDir("det_c");
  sim::writeSequence(sc, 4, 7, a.string(), "0000", {1, false});
  sim::writeSequence(sc, 4, 7, b.string(), "0000", {2, false});  // threads must not matter
  sim::writeSequence(sc, 4, 8, c.string(), "0000", {1, false});
  std::map<std::string, uint64_t> fa, fb;
  EXPECT_EQ(hashTree(a, &fa), hashTree(b, &fb));
  EXPECT_EQ(fa, fb);
  EXPECT_EQ(fa.size(), 4u + 7u);  // 4 scans, label, detections, calib, oxts, poses, scenario.yaml, lidar.yaml
  EXPECT_NE(hashTree(a), hashTree(c));
  for (const fs::path& d : {a, b, c}) fs::remove_all(d);
}

// Writing a shorter sequence over a longer one leaves exactly the new one (no stale scans).
TEST(SimSequence, RewritingAShorterSequenceLeavesNoStaleScans) {
  const sim::Scenario sc = sim::test::shippedScenario("intersection", 5);
  const fs::path dir = tempDir("rewrite");
  sim::writeSequence(sc, 5, 7, dir.string(), "0000", {2, false});
  sim::writeSequence(sc, 3, 7, dir.string(), "0000", {2, false});
  int scans = 0;
  for (const auto& e : fs::directory_iterator(dir / "training" / "velodyne" / "0000")) scans += e.is_regular_file();
  EXPECT_EQ(scans, 3);
  EXPECT_EQ(kitti::SequenceReader(dir.string(), "0000").size(), 3);
  fs::remove_all(dir);
}

TEST(SimSequence, ReaderGetsBackTheGeneratedGroundTruth) {
  const int frames = 6;
  const sim::Scenario sc = sim::test::shippedScenario("urban-static", frames);
  const fs::path dir = tempDir("gt");
  sim::writeSequence(sc, frames, sc.seed, dir.string(), "0003", {2, false});
  ASSERT_TRUE(fs::exists(dir / "scenario.yaml"));
  EXPECT_EQ(sim::loadScenario((dir / "scenario.yaml").string()).seed, sc.seed);
  // How the scans were stored, as the pipeline config's lidar section: the default sensor is KITTI's.
  const YAML::Node lidar = YAML::LoadFile((dir / "lidar.yaml").string())["lidar"];
  EXPECT_DOUBLE_EQ(lidar["sweep_period_s"].as<double>(), sc.frame_period_s);
  EXPECT_TRUE(lidar["sweep_clockwise"].as<bool>());
  EXPECT_DOUBLE_EQ(lidar["vertical_angle_error_deg"].as<double>(), sc.sensor.vertical_angle_error_deg);

  sim::Simulation sim(sc);  // the same scenario and seed: the same drive
  const std::vector<Pose> poses = sim.lidarPoses();
  // The written oxts give the same poses (through the written calibration, the real KITTI one).
  const kitti::Calib calib = kitti::readCalib((dir / "training/calib/0003.txt").string());
  ASSERT_TRUE(calib.T_velo_imu);
  EXPECT_NEAR(calib.P[2](0, 0), 721.5377, 1e-3);
  EXPECT_NEAR(calib.T_cam_velo.translation().z(), -0.2717806, 1e-6);
  const auto from_oxts =
      kitti::oxtsToLidarPoses(kitti::readOxts((dir / "training/oxts/0003.txt").string()), *calib.T_velo_imu);
  ASSERT_EQ(static_cast<int>(from_oxts.size()), frames);
  for (int k = 0; k < frames; ++k) EXPECT_LT((from_oxts[k].translation() - poses[k].translation()).norm(), 1e-3);
  kitti::SequenceReader reader(dir.string(), "0003", {(dir / "detections" / "sim").string()});
  ASSERT_EQ(reader.size(), frames);
  ASSERT_TRUE(reader.hasGroundTruthPoses());
  EXPECT_TRUE(reader.paths().poses_are_lidar);
  EXPECT_TRUE(poses.front().isApprox(Pose::Identity(), 1e-12));
  for (int k = 0; k < frames; ++k) {
    const sim::Simulation::FrameData fd = sim.frame(k);
    const Frame f = reader.read(k);
    ASSERT_TRUE(f.gt_pose);
    EXPECT_LT((f.gt_pose->matrix() - poses[k].matrix()).cwiseAbs().maxCoeff(), 1e-9) << "frame " << k;
    ASSERT_EQ(f.scan.cols(), fd.scan.points.cols());
    EXPECT_EQ(f.scan, fd.scan.points);
    // Labels: every generated row, in the lidar frame, equals what the reader gives.
    std::vector<Box> labels, dontcare;
    for (const kitti::LabelRow& r : fd.labels) {
      Box b = kitti::cameraToLidar(r.box, sim.calib());
      (r.type == "DontCare" ? dontcare : labels).push_back(b);
      b.type = r.type;
    }
    ASSERT_EQ(f.labels.size(), labels.size());
    ASSERT_EQ(f.dontcare.size(), dontcare.size());
    for (size_t i = 0; i < labels.size(); ++i) {
      EXPECT_LT((f.labels[i].center - labels[i].center).norm(), 1e-5);
      EXPECT_LT((f.labels[i].size - labels[i].size).norm(), 1e-5);
      EXPECT_LT(std::abs(wrapAngle(f.labels[i].yaw - labels[i].yaw)), 1e-5);
    }
    // And the label boxes are the simulated objects' boxes moved into this scan's lidar frame.
    const Pose T_lidar_map = fd.input.T_map_lidar.inverse();
    for (const Box& b : f.labels) {
      double best = 1e9;
      for (const Box& o : fd.input.object_boxes)
        best = std::min(best, (o.transformed(T_lidar_map).center - b.center).norm());
      EXPECT_LT(best, 1e-5);
    }
    size_t detections = 0;
    for (const kitti::LabelRow& r : fd.detections) detections += r.type != "DontCare";
    EXPECT_EQ(f.detections.size(), detections);
  }
  fs::remove_all(dir);
}

TEST(SimSequence, OxtsRoundTripRecoversThePosesWithinAMillimetre) {
  // A whole highway drive (~700 m at 25 m/s, with slopes and a curve), through the oxts text file.
  sim::Scenario sc = sim::test::shippedScenario("highway", 300);
  // A rigid ride: the body's pitch and heave on its suspension would show in the rates checked
  // below (the IMU sits a lever arm away from the lidar and feels the heave's acceleration).
  sc.ego.body_pitch_roll = sc.ego.body_heave_m = 0;
  sim::Simulation sim(sc);
  const std::vector<Pose> poses = sim.lidarPoses();
  const fs::path dir = tempDir("oxts");
  fs::create_directories(dir);
  const std::string file = (dir / "oxts.txt").string();
  kitti::writeOxts(file, sim::simulatedOxts(poses, *sim.calib().T_velo_imu, sc.frame_period_s));
  const auto oxts = kitti::readOxts(file);
  const auto from_oxts = kitti::oxtsToLidarPoses(oxts, *sim.calib().T_velo_imu);
  ASSERT_EQ(from_oxts.size(), poses.size());
  double worst = 0, worst_angle = 0;
  for (size_t k = 0; k < poses.size(); ++k) {
    worst = std::max(worst, (from_oxts[k].translation() - poses[k].translation()).norm());
    worst_angle =
        std::max(worst_angle, Eigen::AngleAxisd(from_oxts[k].linear().transpose() * poses[k].linear()).angle());
  }
  EXPECT_LT(worst, 1e-3);
  EXPECT_LT(worst_angle, 1e-6);
  EXPECT_GT((poses.back().translation() - poses.front().translation()).norm(), 500.0);
  // The rates a GPS/IMU reports match the motion: forward speed from the poses, gravity up.
  const double v = (poses[101].translation() - poses[99].translation()).norm() / 0.2;
  EXPECT_NEAR(oxts[100][8], v, 0.05);     // vf
  EXPECT_NEAR(oxts[100][13], 9.81, 0.5);  // az
  fs::remove_all(dir);
}
