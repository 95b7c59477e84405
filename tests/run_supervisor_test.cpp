// dlslot-run's Supervisor: a child's exit is reported once, with its code, however it was
// first noticed (a failing player used to vanish when running() saw its exit before reap()).
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <thread>

#include "supervisor.hpp"

using namespace dlslot::run;
namespace fs = std::filesystem;

namespace {

std::string logPath(const std::string& name) {
  return (fs::temp_directory_path() / ("dlslot_supervisor_" + name + "_" + std::to_string(::getpid()) + ".log"))
      .string();
}

void waitUntilExited(Supervisor& sup, const std::string& name) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (sup.running(name) && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
}

}  // namespace

TEST(RunSupervisor, ExitNoticedByRunningIsStillReportedOnceWithItsCode) {
  Supervisor sup;
  sup.start("failing", {"/bin/sh", "-c", "echo bad input: frame 7 >&2; exit 3"}, logPath("failing"));
  waitUntilExited(sup, "failing");
  ASSERT_FALSE(sup.running("failing"));
  const auto exit = sup.reap();
  ASSERT_TRUE(exit);
  EXPECT_EQ(exit->name, "failing");
  EXPECT_EQ(exit->code, 3);
  EXPECT_EQ(exit->how, "exited with code 3");
  EXPECT_NE(sup.tail("failing").find("bad input: frame 7"), std::string::npos);
  EXPECT_FALSE(sup.reap());  // once
  fs::remove(logPath("failing"));
}

TEST(RunSupervisor, StoppedChildIsNotReported) {
  Supervisor sup;
  sup.start("sleeper", {"/bin/sleep", "30"}, logPath("sleeper"));
  EXPECT_TRUE(sup.running("sleeper"));
  EXPECT_EQ(sup.stop("sleeper", 5.0), 128 + SIGINT);
  EXPECT_FALSE(sup.running("sleeper"));
  EXPECT_FALSE(sup.reap());
  fs::remove(logPath("sleeper"));
}

// The CPU time a child used is known once it has exited: a busy child (copying 10 GB through dd;
// a fast machine copies 2 GB in 0.04 s of CPU) used far more than one that slept as long.
TEST(RunSupervisor, CpuTimeOfExitedChildren) {
  Supervisor sup;
  sup.start("busy", {"/bin/dd", "if=/dev/zero", "of=/dev/null", "bs=1M", "count=10000"}, logPath("busy"));
  sup.start("sleeper", {"/bin/sleep", "0.3"}, logPath("sleeper"));
  EXPECT_LT(sup.cpuSeconds("busy"), 0.0);  // still running
  waitUntilExited(sup, "busy");
  waitUntilExited(sup, "sleeper");
  EXPECT_GT(sup.cpuSeconds("busy"), 0.05);
  EXPECT_GE(sup.cpuSeconds("sleeper"), 0.0);
  EXPECT_LT(sup.cpuSeconds("sleeper"), 0.05);
  fs::remove(logPath("busy"));
  fs::remove(logPath("sleeper"));
}

// The grace of stop() is idle time: a child that keeps working after SIGINT (the renderer writing
// its backlog on a loaded machine) is let finish past the grace; one that ignores SIGINT and
// does nothing is killed once the grace has passed.
TEST(RunSupervisor, StopWaitsForAWorkingChildAndKillsAnIdleOne) {
  Supervisor sup;
  // Ignores SIGINT, then burns CPU for ~1.5 s of its own time and exits 0.
  sup.start("working", {"/bin/sh", "-c", "trap '' INT; end=$(($(date +%s%N) + 1500000000)); "
                                         "while [ $(date +%s%N) -lt $end ]; do :; done; exit 0"},
            logPath("working"));
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_EQ(sup.stop("working", 0.7), 0) << sup.tail("working");
  EXPECT_GT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 0.7);

  sup.start("idle", {"/bin/sh", "-c", "trap '' INT; sleep 30"}, logPath("idle"));
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  const auto t1 = std::chrono::steady_clock::now();
  EXPECT_EQ(sup.stop("idle", 0.7), 128 + SIGKILL);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count(), 5.0);
  fs::remove(logPath("working"));
  fs::remove(logPath("idle"));
}
