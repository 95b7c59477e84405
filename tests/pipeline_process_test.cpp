// The whole pipeline started for real by dlslot-run on a short simulated sequence, inside a
// private network namespace (see tests/CMakeLists.txt): completeness, determinism, replay into a
// fresh backend, and faults.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <signal.h>
#include <thread>

#include "dlslot/associations_t.hpp"
#include "dlslot/node.hpp"
#include "dlslot/odometry_t.hpp"
#include "dlslot/process_status_t.hpp"
#include "dlslot/slot_state_t.hpp"
#include "dlslot/message_auth.hpp"
#include "process_harness.hpp"

using namespace dlslot;
using namespace dlslot::test;
namespace fs = std::filesystem;

namespace {

constexpr int kFrames = 30;

// One simulated sequence for every test of this file (simulated once, into the build tree).
const std::string& simulatedRoot() {
  static const std::string root = [] {
    const std::string dir = binDir() + "/../test-scratch/pipeline-data";
    // Simulated again when the simulator is newer than the cached sequence (its output may differ).
    const bool stale = !fs::exists(dir + "/training/poses/0000.txt") ||
                       fs::last_write_time(dir + "/training/poses/0000.txt") < fs::last_write_time(bin("dlslot-sim"));
    if (stale) {
      fs::remove_all(dir);
      ChildProcess sim({bin("dlslot-sim"), "--scenario", "intersection", "--frames", std::to_string(kFrames), "--seed",
                        "3", "--out", dir},
                       binDir() + "/../test-scratch/pipeline-sim.log");
      EXPECT_EQ(sim.wait(300), 0) << sim.output();
    }
    return dir;
  }();
  return root;
}

std::vector<std::string> runArgs(const std::string& out, std::vector<std::string> extra = {}) {
  std::vector<std::string> a = {bin("dlslot-run"), "--config", config(), "--kitti", simulatedRoot(),
                                "--detections", simulatedRoot() + "/detections/sim", "--out", out, "--quiet"};
  a.insert(a.end(), extra.begin(), extra.end());
  return a;
}

// SLOT_STATE without its wall-clock timings, which legitimately differ between runs.
std::vector<slot_state_t> slotStatesOf(const std::string& log) {
  auto states = decodeAll<slot_state_t>(readLog(log)["SLOT_STATE"]);
  for (auto& s : states) {
    s.timings.clear();
    s.num_timings = 0;
  }
  return states;
}

std::vector<uint8_t> encoded(slot_state_t s) {
  std::vector<uint8_t> buf(s.getEncodedSize());
  s.encode(buf.data(), 0, buf.size());
  return buf;
}

}  // namespace

TEST(PipelineProcess, EveryFrameOnEveryChannelAndMetricsWithinBounds) {
  const std::string out = scratchDir();
  ChildProcess run(runArgs(out), out + "/../pipeline-run.log");
  ASSERT_EQ(run.wait(600), 0) << run.output();
  auto events = readLog(out + "/run.lcmlog");
  for (const std::string ch : {"LIDAR_SCAN", "DETECTIONS", "GROUND_TRUTH", "ODOMETRY", "ASSOCIATIONS", "SLOT_STATE"})
    EXPECT_EQ(events[ch].size(), static_cast<size_t>(kFrames)) << ch;
  const auto states = decodeAll<slot_state_t>(events["SLOT_STATE"]);
  for (int i = 0; i < static_cast<int>(states.size()); ++i) {
    EXPECT_EQ(states[i].frame, i);
    EXPECT_FALSE(states[i].odometry_missing) << i;
    EXPECT_FALSE(states[i].associations_missing) << i;
  }
  EXPECT_GT(states.back().num_tracks, 0);
  // Every process reported, with no decode errors, gaps or timeouts.
  const auto status = decodeAll<process_status_t>(events["PROCESS_STATUS"]);
  std::map<std::string, process_status_t> last;
  for (const auto& s : status) last[s.name] = s;
  for (const std::string p : {"player", "odometry", "tracker", "backend", "renderer", "mapper"}) {
    ASSERT_TRUE(last.count(p)) << p;
#ifdef __SANITIZE_ADDRESS__
    // ./dlslot test --sanitize: several times slower, so inputs may miss their time limits.
    EXPECT_EQ(last[p].decode_errors + last[p].frame_gaps, 0) << p << ": " << last[p].last_warning;
#else
    EXPECT_EQ(last[p].decode_errors + last[p].frame_gaps + last[p].timeouts, 0) << p << ": " << last[p].last_warning;
#endif
  }
  // Outputs and metrics.
  for (const std::string f : {"metrics.json", "report.md", "trajectory_slot_kitti.txt", "trajectory_odometry_kitti.txt",
                              "trajectory_groundtruth_kitti.txt", "trajectory_slot_tum.txt", "tracks_kitti.txt",
                              "config.yaml", "bev/000000.png", "map.pcd", "map_removed.pcd", "map.png",
                              "trajectory_map_kitti.txt", "trajectory_map_tum.txt", "trajectory_map_kitti_cam.txt"})
    EXPECT_TRUE(fs::exists(out + "/" + f)) << f;
  const YAML::Node m = YAML::LoadFile(out + "/metrics.json");
  EXPECT_LT(m["ego.ate_rmse_m"].as<double>(), 1.0);
  EXPECT_GT(m["tracking.mota"].as<double>(), 0.3);
  EXPECT_EQ(m["frames.SLOT_STATE"].as<int>(), kFrames);
  // The mapper: a MAP_STATE per scan, a static map that keeps the scene and drops the traffic.
  EXPECT_EQ(events["MAP_STATE"].size(), static_cast<size_t>(kFrames));
  EXPECT_GT(m["map.sa"].as<double>(), 0.9);
  EXPECT_GT(m["map.da"].as<double>(), 0.5);
  EXPECT_EQ(m["map.loops_false"].as<int>(), 0);
  EXPECT_LT(m["sources.map.ate_rmse_m"].as<double>(), 1.0);
}

TEST(PipelineProcess, SameRunTwiceGivesIdenticalSlotState) {
  const std::string out = scratchDir();
  for (const std::string r : {"a", "b"}) {
    ChildProcess run(runArgs(out + "/" + r, {"--no-render", "--no-eval"}), out + "/" + r + ".log");
    ASSERT_EQ(run.wait(600), 0) << run.output();
  }
  const auto a = slotStatesOf(out + "/a/run.lcmlog"), b = slotStatesOf(out + "/b/run.lcmlog");
  ASSERT_EQ(a.size(), static_cast<size_t>(kFrames));
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) EXPECT_EQ(encoded(a[i]), encoded(b[i])) << "frame " << i;
}

// dlslot-run's lockstep keeps two frames in flight (the odometry of t+1 runs while the backend
// solves t; the tracker waits for SLOT_STATE t before associating t+1): the same results as
// strict lockstep (--in-flight 1), to the byte, and the overlap really happens.
TEST(PipelineProcess, FramesInFlightGiveStrictLockstepResults) {
  const std::string out = scratchDir();
  for (const std::string n : {"1", "2"}) {
    ChildProcess run(runArgs(out + "/in-flight-" + n, {"--no-render", "--in-flight", n}), out + "/" + n + ".log");
    ASSERT_EQ(run.wait(600), 0) << run.output();
  }
  const std::string strict = out + "/in-flight-1", overlap = out + "/in-flight-2";
  for (const std::string f : {"trajectory_slot_kitti.txt", "trajectory_slot_smoothed_kitti.txt",
                              "trajectory_odometry_kitti.txt", "tracks_kitti.txt"})
    EXPECT_EQ(readText(strict + "/" + f), readText(overlap + "/" + f)) << f;
  const auto a = slotStatesOf(strict + "/run.lcmlog"), b = slotStatesOf(overlap + "/run.lcmlog");
  ASSERT_EQ(a.size(), static_cast<size_t>(kFrames));
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) EXPECT_EQ(encoded(a[i]), encoded(b[i])) << "frame " << i;
  // The logger's order: with two frames in flight, scan t+1 is out before SLOT_STATE t (never
  // in strict lockstep).
  auto scanBeforeSlot = [](const std::string& log) {
    int frames = 0;
    std::map<int, bool> slot_seen;
    lcm::LogFile f(log, "r");
    for (const lcm::LogEvent* e = f.readNextEvent(); e; e = f.readNextEvent()) {
      // The run authenticates its messages: the LCM bytes sit inside the envelope (message_auth.hpp).
      const bool sealed = isEnvelope(e->data, e->datalen);
      const uint8_t* data = static_cast<const uint8_t*>(e->data) + (sealed ? kEnvelopeHeader : 0);
      const int frame = frameOfEncoded(data, e->datalen - (sealed ? kEnvelopeHeader + kEnvelopeTag : 0));
      if (e->channel == "SLOT_STATE") slot_seen[frame] = true;
      if (e->channel == "LIDAR_SCAN" && frame > 0 && !slot_seen[frame - 1]) ++frames;
    }
    return frames;
  };
  EXPECT_EQ(scanBeforeSlot(strict + "/run.lcmlog"), 0);
  EXPECT_GT(scanBeforeSlot(overlap + "/run.lcmlog"), kFrames / 3);
}

TEST(PipelineProcess, ReplayedBackendInputsGiveTheSameSlotState) {
  const std::string out = scratchDir();
  ChildProcess run(runArgs(out + "/run", {"--no-render", "--no-eval"}), out + "/run.log");
  ASSERT_EQ(run.wait(600), 0) << run.output();

  ChildProcess logger({"/usr/bin/lcm-logger", "--quiet", "--force", "--channel=SLOT_STATE", out + "/replay.lcmlog"},
                      out + "/logger.log");
  // The replay verifies with the run's key, which the run folder keeps (message_auth.hpp).
  ChildProcess backend({bin("dlslot-backend"), "--config", config(), "--mode", "slot", "--key", out + "/run/run.key"},
                       out + "/backend.log");
  std::this_thread::sleep_for(std::chrono::seconds(1));
  ChildProcess player({"/usr/bin/lcm-logplayer", "--speed=1", "--regexp=^(LIDAR_SCAN|ODOMETRY|ASSOCIATIONS)$",
                       out + "/run/run.lcmlog"},
                      out + "/logplayer.log");
  ASSERT_EQ(player.wait(120), 0) << player.output();
  std::this_thread::sleep_for(std::chrono::seconds(2));
  EXPECT_EQ(backend.stop(), 0) << backend.output();
  EXPECT_EQ(logger.stop(), 0);
  EXPECT_NE(backend.output().find("messages authenticated with the run key"), std::string::npos) << backend.output();
  EXPECT_EQ(backend.output().find("refused a message"), std::string::npos) << backend.output();
  const auto original = slotStatesOf(out + "/run/run.lcmlog"), replayed = slotStatesOf(out + "/replay.lcmlog");
  ASSERT_EQ(replayed.size(), original.size());
  for (size_t i = 0; i < original.size(); ++i) EXPECT_EQ(encoded(replayed[i]), encoded(original[i])) << "frame " << i;
}

TEST(PipelineProcess, KilledTrackerIsReportedAndTheLogKept) {
  const std::string out = scratchDir();
  // Rate mode at half speed: 30 frames take 6 s, so the tracker dies mid-run.
  ChildProcess run(runArgs(out, {"--no-render", "--no-eval", "--speed", "0.5"}), out + "/../killed-run.log");
  // This run's own tracker (other tests may run trackers at the same time): a child of dlslot-run.
  const std::string pidof =
      "pgrep -P " + std::to_string(run.pid()) + " -f 'bin/[d]lslot-tracker' > " + out + "/tracker.pid";
  for (int i = 0; i < 400 && !fs::exists(out + "/logs/player.log"); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  std::this_thread::sleep_for(std::chrono::seconds(2));
  ASSERT_EQ(std::system(pidof.c_str()), 0);
  int pid = 0;
  std::ifstream(out + "/tracker.pid") >> pid;
  ASSERT_GT(pid, 0);
  kill(pid, SIGKILL);
  const int code = run.wait(120);
  EXPECT_NE(code, 0);
  EXPECT_NE(code, -1);
  const std::string text = run.output();
  EXPECT_NE(text.find("tracker killed by signal 9"), std::string::npos) << text;
  EXPECT_TRUE(fs::exists(out + "/run.lcmlog"));
  EXPECT_FALSE(readLog(out + "/run.lcmlog")["LIDAR_SCAN"].empty());
}

TEST(PipelineProcess, BadConfigIsRefusedBeforeAnyProcessStarts) {
  const std::string out = scratchDir();
  const std::string shipped = config();
  const std::string text = readText(shipped);
  struct Case {
    std::string name, yaml, expect;
  };
  std::string unknown = text, wrong = text;
  unknown.replace(unknown.find("tracker:\n"), 9, "tracker:\n  no_such_key: 1\n");
  wrong.replace(wrong.find("lockstep_timeout_s:"), 19, "lockstep_timeout_s: soon #");
  for (const Case& c : {Case{"unknown", unknown, "tracker.no_such_key"}, Case{"wrong", wrong, "player.lockstep_timeout_s"},
                        Case{"missing", "", "cannot open config file"}}) {
    const std::string file = out + "/" + c.name + ".yaml";
    if (!c.yaml.empty()) std::ofstream(file) << c.yaml;
    std::vector<std::string> args = runArgs(out + "/" + c.name);
    args[2] = file;
    ChildProcess run(args, out + "/" + c.name + ".log");
    EXPECT_EQ(run.wait(60), 2) << c.name << ": " << run.output();
    EXPECT_NE(run.output().find(c.expect), std::string::npos) << c.name << ": " << run.output();
    EXPECT_FALSE(fs::exists(out + "/" + c.name + "/run.lcmlog")) << c.name;
  }
}
