// No process of a run outlives the launcher. dlslot-run is killed with SIGKILL
// (no chance to stop anything) while its pipeline plays; every child it had must be gone soon
// after (the kernel's parent-death signal, tools/run/supervisor.cpp).
#include <gtest/gtest.h>
#include <signal.h>

#include <filesystem>
#include <thread>

#include "process_harness.hpp"

using namespace dlslot::test;
namespace fs = std::filesystem;

namespace {

// Running (not gone, not a zombie waiting to be reaped).
bool alive(pid_t pid) {
  const auto s = procStat(pid);
  return s && s->state != 'Z' && s->state != 'X';
}

}  // namespace

TEST(RunOrphansProcess, SigkillOfTheLauncherLeavesNoChildRunning) {
  ASSERT_TRUE(insidePrivateNetwork());
  const std::string out = scratchDir();
  ChildProcess sim({bin("dlslot-sim"), "--scenario", "intersection", "--frames", "40", "--seed", "2", "--out",
                    out + "/data"},
                   out + "/sim.log");
  ASSERT_EQ(sim.wait(300), 0) << sim.output();
  // Rate mode at a quarter of real time: 40 frames take 16 s, so the pipeline is mid-run when killed.
  ChildProcess run({bin("dlslot-run"), "--config", config(), "--kitti", out + "/data", "--detections",
                    out + "/data/detections/sim", "--out", out + "/run", "--speed", "0.25", "--quiet"},
                   out + "/run.log");
  for (int i = 0; i < 600 && !fs::exists(out + "/run/logs/player.log"); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  std::this_thread::sleep_for(std::chrono::seconds(2));
  ASSERT_TRUE(run.running()) << run.output();
  const std::set<pid_t> children = childrenOf(run.pid());
  // lcm-logger, renderer, mapper, backend, tracker, odometry and the player.
  ASSERT_EQ(children.size(), 7u) << run.output();

  kill(run.pid(), SIGKILL);
  EXPECT_EQ(run.wait(10), 128 + SIGKILL);
  std::set<pid_t> left = children;
  for (int i = 0; i < 200 && !left.empty(); ++i) {
    for (auto it = left.begin(); it != left.end();) it = alive(*it) ? std::next(it) : left.erase(it);
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  std::string names;
  for (pid_t p : left) {
    const auto s = procStat(p);
    names += " " + (s ? s->comm : std::string("?")) + "(" + std::to_string(p) + ")";
    kill(p, SIGKILL);  // do not leave them to the next test
  }
  EXPECT_TRUE(left.empty()) << left.size() << " of " << children.size() << " children survived the launcher:" << names;
  std::cout << "[ orphans ] " << children.size() << " children, " << left.size() << " alive 10 s after SIGKILL\n";
}
