// A stall is seen per process, not only for the whole pipeline. The odometry is
// stopped with SIGSTOP mid-run (alive, silent, holding its frames); the launcher must name it as
// stalled once its heartbeat (PROCESS_STATUS, 1 Hz) has been missing for --heartbeat-timeout
// seconds, exit 3, and leave nothing running.
#include <gtest/gtest.h>
#include <fstream>
#include <sstream>
#include <signal.h>

#include <filesystem>
#include <thread>

#include "process_harness.hpp"

using namespace dlslot::test;
namespace fs = std::filesystem;

namespace {

// The pid of the child of `parent` running `comm`, or -1.
pid_t childNamed(pid_t parent, const std::string& comm) {
  for (pid_t pid : childrenOf(parent)) {
    const auto s = procStat(pid);
    if (s && s->comm == comm) return pid;
  }
  return -1;
}

// `frames` of the intersection simulated into OUT/data; dlslot-run's arguments for them (into
// OUT/run, no renderer, no evaluation) with `extra`, under the config file `cfg`.
std::vector<std::string> runOnSimulated(const std::string& out, int frames, const std::vector<std::string>& extra,
                                        const std::string& cfg = config()) {
  ChildProcess sim({bin("dlslot-sim"), "--scenario", "intersection", "--frames", std::to_string(frames), "--seed", "3",
                    "--out", out + "/data"},
                   out + "/sim.log");
  EXPECT_EQ(sim.wait(300), 0) << sim.output();
  std::vector<std::string> a = {bin("dlslot-run"), "--config", cfg, "--kitti", out + "/data", "--detections",
                                out + "/data/detections/sim", "--out", out + "/run", "--quiet", "--no-render",
                                "--no-eval"};
  a.insert(a.end(), extra.begin(), extra.end());
  return a;
}

// The run's odometry once about three scans (5 MB) are in the run's log: mid-run, whatever the
// machine's speed (lockstep plays ~30 frames a second). -1: the run or its odometry is gone.
pid_t odometryMidRun(ChildProcess& run, const std::string& out) {
  const std::string log = out + "/run/run.lcmlog";
  std::error_code ec;
  for (int i = 0; i < 6000 && run.running() && !(fs::file_size(log, ec) >= 5'000'000 && !ec); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  return run.running() ? childNamed(run.pid(), "dlslot-odometry") : -1;
}

}  // namespace

TEST(RunStallProcess, StoppedOdometryIsReportedByName) {
  ASSERT_TRUE(insidePrivateNetwork());
  const std::string out = scratchDir();
  // Rate mode at a quarter of real time (40 frames in 16 s): the odometry is stopped mid-run, long
  // before the pipeline-wide stall timeout (60 s) could fire.
  ChildProcess run(runOnSimulated(out, 40, {"--speed", "0.25", "--heartbeat-timeout", "3"}), out + "/run.log");
  const pid_t odometry = odometryMidRun(run, out);
  ASSERT_GT(odometry, 0) << run.output();

  const auto stopped_at = std::chrono::steady_clock::now();
  ASSERT_EQ(kill(odometry, SIGSTOP), 0);
  const int code = run.wait(60);
  const double after_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - stopped_at).count();
  const std::string text = run.output();
  EXPECT_EQ(code, 3) << text;
  EXPECT_NE(text.find("odometry stalled: no PROCESS_STATUS (heartbeat) for 3 s"), std::string::npos) << text;
  EXPECT_EQ(text.find("pipeline stalled"), std::string::npos) << text;
  EXPECT_LT(after_s, 20.0) << "the stall took " << after_s << " s to be reported";
  // The stopped process was ended with the run (SIGKILL reaches a stopped process).
  for (int i = 0; i < 100 && kill(odometry, 0) == 0; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  const bool gone = kill(odometry, 0) != 0;
  if (!gone) kill(odometry, SIGKILL);
  EXPECT_TRUE(gone) << "the stopped odometry outlived the launcher";
  std::cout << "[ stall ] odometry SIGSTOPped; the launcher reported it by name after " << after_s << " s (exit "
            << code << ")\n";
}

// In lockstep a process that is only slow (a loaded machine, a sanitizer build) changes nothing:
// no later frame comes before this one is solved, so the backend and the tracker wait for its
// input as long as the player's lockstep timeout allows (0.4 of it each) instead of going on
// without it; the mapper holds a scan as long as the player may wait for the SLOT_STATEs before
// it. The odometry is stopped for 1.5 s, longer than the backend's own live wait
// (backend.join_timeout_s, 1 s) and the mapper's (set to 1 s here), shorter than the lockstep's
// (0.4 x 5 s).
TEST(RunStallProcess, SlowOdometryInLockstepLosesNothing) {
  ASSERT_TRUE(insidePrivateNetwork());
  const std::string out = scratchDir();
  // The mapper's wait, found by its comment (every process has a join_timeout_s).
  const std::string cfg = configWith(out, "short-mapper-wait", "join_timeout_s: 5.0         # live: how long a scan waits",
                                     "join_timeout_s: 1.0         # live: how long a scan waits");
  ChildProcess run(runOnSimulated(out, 60, {}, cfg), out + "/run.log");
  const pid_t odometry = odometryMidRun(run, out);
  ASSERT_GT(odometry, 0) << run.output();
  ASSERT_EQ(kill(odometry, SIGSTOP), 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  ASSERT_EQ(kill(odometry, SIGCONT), 0);
  const int code = run.wait(120);
  const std::string text = run.output();
  EXPECT_EQ(code, 0) << text;
  EXPECT_NE(text.find("solved without odometry 0, without associations 0"), std::string::npos) << text;
  EXPECT_NE(text.find("0 frames lost"), std::string::npos) << text;
}
