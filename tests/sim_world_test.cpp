// Scenarios and the simulated world: every shipped scenario loads, bad files are rejected with
// the file and key named; no two solids ever overlap; paths are smooth; the highway surrounds
// the ego with cars at its speed.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>

#include "dlslot/config.hpp"
#include "sim/simulation.hpp"
#include "sim_scenario.hpp"

namespace fs = std::filesystem;
using namespace dlslot;

namespace {


std::string writeTemp(const std::string& text) {
  const fs::path p = fs::temp_directory_path() / ("dlslot_sim_scenario_" + std::to_string(::getpid()) + ".yaml");
  std::ofstream(p) << text;
  return p.string();
}

std::string errorOf(const std::string& yaml) {
  try {
    sim::loadScenario(writeTemp(yaml));
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

const char* kMinimal = R"(name: tiny
roads:
  - name: main
    route: {start: [0, 0, 0], pieces: [{straight: 100}]}
    lanes: [-1.75, 1.75]
    carriageway_m: 7
    clear_m: 20
ego:
  road: main
  lane: -1.75
  speed_mps: [[0, 5]]
)";

}  // namespace

TEST(SimScenario, ShippedScenariosLoadByName) {
  // urban-static is longer (450 frames, ~390 m) so that KITTI's 100-800 m t_rel has more than two segment lengths.
  const std::map<std::string, int> frames{{"urban-static", 450}, {"intersection", 300}, {"highway", 300}, {"parking-lot", 300}};
  for (const auto& [name, expected_frames] : frames) {
    const sim::Scenario sc = sim::loadScenario(sim::resolveScenario(name, DLSLOT_SOURCE_DIR));
    EXPECT_EQ(sc.name, name);
    EXPECT_EQ(sc.frames, expected_frames);
    EXPECT_FALSE(sc.roads.empty());
  }
  EXPECT_THROW(sim::resolveScenario("no-such-scenario", DLSLOT_SOURCE_DIR), ConfigError);
}

TEST(SimScenario, BadFilesNameTheFileAndTheKey) {
  EXPECT_EQ(errorOf(kMinimal), "");
  const std::string unknown = errorOf(std::string(kMinimal) + "colour: red\n");
  EXPECT_NE(unknown.find("colour"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("unknown key"), std::string::npos) << unknown;
  const std::string road = errorOf(
      std::string(kMinimal) + "traffic:\n  - {road: side, lane: 1, classes: {Car: 1}, count: 1, speed_mps: [1, 2]}\n");
  EXPECT_NE(road.find("traffic[0].road"), std::string::npos) << road;
  EXPECT_NE(road.find("no road named 'side'"), std::string::npos) << road;
  const std::string cls = errorOf(
      std::string(kMinimal) + "traffic:\n  - {road: main, lane: 1, classes: {Tank: 1}, count: 1, speed_mps: [1, 2]}\n");
  EXPECT_NE(cls.find("unknown class 'Tank'"), std::string::npos) << cls;
  std::string no_lanes = kMinimal;
  no_lanes.replace(no_lanes.find("    lanes: [-1.75, 1.75]\n"), 25, "");
  const std::string missing = errorOf(no_lanes);
  EXPECT_NE(missing.find("roads[0].lanes"), std::string::npos) << missing;
  EXPECT_NE(missing.find(".yaml"), std::string::npos) << missing;
  const std::string interval = errorOf(std::string(kMinimal) + "ground: {wavelength_m: [400, 100]}\n");
  EXPECT_NE(interval.find("ground.wavelength_m"), std::string::npos) << interval;
}

TEST(SimScenario, TheDetectorsAcrossKeysDefaultToTheAlongOnes) {
  // The across drift's time follows drift_time_s unless given; the white noise is the same both
  // ways unless the ratio is given, and a ratio must be positive.
  const sim::Scenario drift = sim::loadScenario(writeTemp(std::string(kMinimal) + "detector: {drift_time_s: 2}\n"));
  EXPECT_DOUBLE_EQ(drift.detector.drift_across_time_s, 2.0);
  EXPECT_DOUBLE_EQ(drift.detector.position_noise_across_ratio, 1.0);
  const sim::Scenario across = sim::loadScenario(writeTemp(
      std::string(kMinimal) +
      "detector: {drift_time_s: 2, drift_across_time_s: 1.3, position_noise_across_ratio: 0.6}\n"));
  EXPECT_DOUBLE_EQ(across.detector.drift_time_s, 2.0);
  EXPECT_DOUBLE_EQ(across.detector.drift_across_time_s, 1.3);
  EXPECT_DOUBLE_EQ(across.detector.position_noise_across_ratio, 0.6);
  const std::string zero = errorOf(std::string(kMinimal) + "detector: {position_noise_across_ratio: 0}\n");
  EXPECT_NE(zero.find("detector.position_noise_across_ratio"), std::string::npos) << zero;
}

TEST(SimWorld, NoSolidsOverlapAndMotionIsSmooth) {
  for (const std::string name : {"urban-static", "intersection", "highway", "parking-lot"}) {
    const sim::Scenario sc = sim::test::shippedScenario(name, 120);
    const sim::World world = sim::buildWorld(sc);
    const sim::Motion motion = sim::simulateMotion(sc, world);
    ASSERT_EQ(static_cast<int>(motion.ego.size()), sc.frames);
    for (int f = 0; f < sc.frames; f += 3) {
      std::vector<Box> boxes;
      for (const sim::Agent& a : motion.agents) boxes.push_back(sim::agentBox(a, f, *world.ground));
      for (size_t i = 0; i < boxes.size(); ++i) {
        const sim::Solid si = sim::Solid::box(boxes[i].center, boxes[i].size, boxes[i].yaw, 0);
        for (size_t j = i + 1; j < boxes.size(); ++j)
          ASSERT_FALSE(sim::overlaps(si, sim::Solid::box(boxes[j].center, boxes[j].size, boxes[j].yaw, 0), 0.0))
              << name << " frame " << f << ": objects " << i << " and " << j;
        const Eigen::Vector2d c = boxes[i].center.head<2>(), r = Eigen::Vector2d::Constant(boxes[i].size.norm());
        for (int k : world.grid->near(c - r, c + r))
          ASSERT_FALSE(sim::overlaps(si, world.grid->solids()[k], 0.0)) << name << " frame " << f << ": object " << i;
        // The ego never drives through an object (its lidar is 1.73 m above its own footprint).
        const Eigen::Vector3d ego = motion.ego[f].translation();
        EXPECT_GT((boxes[i].center - ego).head<2>().norm(), 1.0) << name << " frame " << f;
      }
    }
    // The ego's motion is smooth: bounded acceleration and yaw rate, no jumps.
    const double dt = sc.frame_period_s;
    for (int f = 2; f < sc.frames; ++f) {
      const Eigen::Vector3d p0 = motion.ego[f - 2].translation(), p1 = motion.ego[f - 1].translation(),
                            p2 = motion.ego[f].translation();
      EXPECT_LT(((p2 - 2 * p1 + p0) / (dt * dt)).norm(), 6.0) << name << " frame " << f;
      const double yaw_rate =
          Eigen::AngleAxisd(motion.ego[f - 1].linear().transpose() * motion.ego[f].linear()).angle() / dt;
      EXPECT_LT(yaw_rate, 0.8) << name << " frame " << f;
    }
    // The ego stands on the ground: its lidar is 1.73 m above it.
    const Eigen::Vector3d p = motion.ego[0].translation();
    EXPECT_NEAR(p.z() - world.ground->height(p.head<2>()), sc.sensor.height_m, 0.01 + 3 * sc.ego.body_heave_m) << name;
  }
}

TEST(SimWorld, TheKittiRideRocksLikeKittisPosesAndRestsWhenStopped) {
  // KITTI's GPS/INS poses (tracking train 0000-0009, scripts/body-ride.py): the pitch-and-roll
  // change from frame to frame is 0.08-0.21 deg rms above 2 m/s and 0.007 standing. The ride set
  // from them (0.1 deg, full from 2 m/s) must fall in that range while driving, vanish at rest and
  // grow in proportion between; the default ride (0.5 deg at every speed) is 5x harder.
  sim::EgoSpec kitti;
  kitti.body_pitch_roll = 0.1 * M_PI / 180.0;
  kitti.ride_full_speed_mps = 2.0;
  auto rmsChangeDeg = [](const sim::BodyRide& ride, double speed) {
    double sum = 0;
    const int n = 10000;
    for (int f = 1; f <= n; ++f) {
      const Eigen::Matrix3d R = ride.at(0.1 * (f - 1), speed).linear().transpose() * ride.at(0.1 * f, speed).linear();
      const double roll = std::atan2(R(2, 1), R(2, 2)), pitch = std::asin(-R(2, 0));
      sum += roll * roll + pitch * pitch;
    }
    return std::sqrt(sum / n) * 180.0 / M_PI;
  };
  const sim::BodyRide ride(kitti, 7), old_ride(sim::EgoSpec(), 7);
  const double driving = rmsChangeDeg(ride, 10.0), crawling = rmsChangeDeg(ride, 1.0), resting = rmsChangeDeg(ride, 0.0);
  const double old_driving = rmsChangeDeg(old_ride, 10.0), old_resting = rmsChangeDeg(old_ride, 0.0);
  std::printf("pitch-and-roll change a frame: KITTI ride %.3f deg at 10 m/s, %.3f at 1 m/s, %.4f at rest; default %.3f / %.3f\n",
              driving, crawling, resting, old_driving, old_resting);
  EXPECT_GT(driving, 0.08);
  EXPECT_LT(driving, 0.21);
  EXPECT_NEAR(crawling, 0.5 * driving, 1e-5);  // small angles: the composition is nearly linear
  EXPECT_EQ(resting, 0.0);
  EXPECT_TRUE(ride.at(3.0, 0.0).isApprox(Pose::Identity()));
  EXPECT_NEAR(ride.at(3.0, 25.0).translation().z(), ride.at(3.0, 2.0).translation().z(), 1e-12);  // full from 2 m/s
  EXPECT_NEAR(old_resting, old_driving, 1e-12);  // the default: the same ride at every speed
  EXPECT_GT(old_driving, 4 * driving);
}

TEST(SimWorld, HighwaySurroundsTheEgoWithCarsAtItsSpeed) {
  const sim::Scenario sc = sim::test::shippedScenario("highway", 100);
  const sim::World world = sim::buildWorld(sc);
  const sim::Motion motion = sim::simulateMotion(sc, world);
  for (int f : {0, 50, 99}) {
    const Eigen::Vector3d ego = motion.ego[f].translation();
    const double ego_speed = (motion.ego[f].translation() - motion.ego[f > 0 ? f - 1 : 1].translation()).norm() / 0.1;
    int near = 0, overtaking = 0;
    for (const sim::Agent& a : motion.agents) {
      if ((a.xy[f] - ego.head<2>()).norm() > 80.0) continue;  // well within the lidar's view
      const double dv = a.speed[f] - ego_speed;
      const bool same_direction = std::cos(a.heading[f] - std::atan2(motion.ego[f](1, 0), motion.ego[f](0, 0))) > 0;
      if (same_direction && std::abs(dv) < 6.0) ++near;
      if (same_direction && dv > 2.0) ++overtaking;
    }
    EXPECT_GE(near, 10) << "frame " << f;
    EXPECT_GE(overtaking, 1) << "frame " << f;
  }
}
