// What a hostile (or careless) user can hand dlslot-run, each refused with a message naming the
// option, key or file, or handled as docs/security.md says; every case here once went through
// without a word or failed in a misleading way:
//   4. two channels with one name (channels.odometry: SLOT_STATE): exit 0, no trajectory, no tracks;
//   5. player.lockstep_timeout_s: -5.0 (frames lost) or .nan (exit 0);
//   6. a second run on the same LCM URL: each refused the other's messages, the second stalled;
//   8. a SIGSTOPped node in rate mode at the default heartbeat timeout: "did not exit cleanly";
//   9. a 0-byte scan played as a 0-point frame; "000000.bin .. 28.bin" for a 30-scan sequence;
//      --speed 0/-1/nan meaning lockstep; --frames -3 playing everything; --heartbeat-timeout 0;
//      a full disk under run.lcmlog reported with no lines; ./dlslot resolving relative paths
//      against the repository instead of the caller's directory.
// (Case 7, the kernel drop count, is checked in pipeline_hostile_process_test.)
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <signal.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "dlslot/message_auth.hpp"
#include "dlslot/node.hpp"
#include "process_harness.hpp"

using namespace dlslot;
using namespace dlslot::test;
namespace fs = std::filesystem;

namespace {

// One simulated sequence for every case here (made once per test binary).
const std::string& data() {
  static const std::string dir = [] {
    const std::string d = binDir() + "/../test-scratch/RunHostileInput.data";
    if (!fs::exists(d + "/done")) {
      fs::remove_all(d);
      ChildProcess sim({bin("dlslot-sim"), "--scenario", "intersection", "--frames", "30", "--seed", "2", "--out", d},
                       d + ".log");
      EXPECT_EQ(sim.wait(300), 0) << sim.output();
      std::ofstream(d + "/done") << "1";
    }
    return d;
  }();
  return dir;
}

std::vector<std::string> runArgs(const std::string& out, std::vector<std::string> extra = {},
                                  const std::string& root = data()) {
  std::vector<std::string> a = {bin("dlslot-run"), "--config", config(), "--kitti", root,
                                "--detections", root + "/detections/sim", "--out", out, "--quiet"};
  a.insert(a.end(), extra.begin(), extra.end());
  return a;
}

pid_t childNamed(pid_t parent, const std::string& comm) {
  for (pid_t pid : childrenOf(parent)) {
    const auto s = procStat(pid);
    if (s && s->comm == comm) return pid;
  }
  return -1;
}

// A copy of the data whose scans can be changed.
std::string copyOfData(const std::string& dir) {
  fs::remove_all(dir);
  fs::copy(data(), dir, fs::copy_options::recursive);
  return dir;
}

}  // namespace

TEST(RunHostileInputProcess, DuplicateChannelNamesAndBadConfigValuesAreRefusedByKey) {
  const std::string out = scratchDir();
  struct Case {
    std::string name, from, to, expect;
  };
  for (const Case& c : {Case{"same-channel", "  odometry: ODOMETRY", "  odometry: SLOT_STATE",
                             "channels.slot_state: channel 'SLOT_STATE' is already channels.odometry"},
                        Case{"negative-timeout", "lockstep_timeout_s: ", "lockstep_timeout_s: -5.0 #",
                             "player.lockstep_timeout_s: expected > 0 s"},
                        Case{"nan-timeout", "lockstep_timeout_s: ", "lockstep_timeout_s: .nan #",
                             "player.lockstep_timeout_s (line"}}) {
    std::vector<std::string> args = runArgs(out + "/" + c.name);
    args[2] = configWith(out, c.name, c.from, c.to);
    ChildProcess run(args, out + "/" + c.name + ".log");
    EXPECT_EQ(run.wait(60), 2) << c.name << ": " << run.output();
    EXPECT_NE(run.output().find(c.expect), std::string::npos) << c.name << ": " << run.output();
    EXPECT_FALSE(fs::exists(out + "/" + c.name + "/run.lcmlog")) << c.name;
  }
  // .nan names what was expected.
  ChildProcess nan({bin("dlslot-player"), "--config", configWith(out, "nan2", "lockstep_timeout_s: ", "lockstep_timeout_s: .nan #"),
                    "--check-config"},
                   out + "/nan-player.log");
  EXPECT_EQ(nan.wait(30), 2);
  EXPECT_NE(nan.output().find("expected a number, got '.nan'"), std::string::npos) << nan.output();
}

TEST(RunHostileInputProcess, BadOptionValuesAreRefusedByName) {
  const std::string out = scratchDir();
  struct Case {
    std::vector<std::string> args;
    std::string expect;
    int code = 2;  // a bad command line; 1: a bad file
  };
  for (const Case& c : {Case{{"--speed", "0"}, "--speed: expected a real-time factor > 0"},
                        Case{{"--speed", "-1"}, "--speed: expected a real-time factor > 0"},
                        Case{{"--speed", "nan"}, "--speed: expected a finite number, got 'nan'"},
                        Case{{"--frames", "-3"}, "--frames: expected a number of frames >= 1, got -3"},
                        Case{{"--frames", "0"}, "--frames: expected a number of frames >= 1, got 0"},
                        Case{{"--heartbeat-timeout", "0"}, "--heartbeat-timeout: expected seconds > 0"},
                        Case{{"--heartbeat-timeout", "1"}, "--heartbeat-timeout: expected >= 2 s"},
                        Case{{"--stall-timeout", "-1"}, "--stall-timeout: expected seconds > 0"},
                        Case{{"--key", out + "/none.key"}, "none.key: key file not found", 1},
                        Case{{"--insecure", "--key", out + "/none.key"}, "--insecure and --key exclude each other"}}) {
    ChildProcess run(runArgs(out + "/run", c.args), out + "/opt.log");
    EXPECT_EQ(run.wait(60), c.code) << c.args[0] << " " << c.args[1] << ": " << run.output();
    EXPECT_NE(run.output().find(c.expect), std::string::npos) << c.args[0] << " " << c.args[1] << ": " << run.output();
    EXPECT_FALSE(fs::exists(out + "/run/run.lcmlog"));
  }
  // A key file others may read is refused naming it and the fix.
  const std::string key = out + "/open.key";
  ChildProcess make({bin("dlslot-run"), "--make-key", key}, out + "/make.log");
  ASSERT_EQ(make.wait(30), 0) << make.output();
  fs::permissions(key, fs::perms::group_read, fs::perm_options::add);
  ChildProcess run(runArgs(out + "/run", {"--key", key}), out + "/key.log");
  EXPECT_NE(run.wait(60), 0);
  EXPECT_NE(run.output().find("chmod 600 " + key), std::string::npos) << run.output();
}

TEST(RunHostileInputProcess, ScanFilesThatAreNotScansAreNamed) {
  const std::string out = scratchDir();
  // A 0-byte scan: the player stops on it, naming the file.
  const std::string empty = copyOfData(out + "/empty");
  fs::resize_file(empty + "/training/velodyne/0000/000005.bin", 0);
  ChildProcess run(runArgs(out + "/run-empty", {"--no-eval", "--no-render"}, empty), out + "/empty.log");
  EXPECT_NE(run.wait(120), 0) << run.output();
  EXPECT_NE(run.output().find("000005.bin: empty scan (0 bytes"), std::string::npos) << run.output();
  // A missing scan: the range named is the sequence's (000000.bin .. 000029.bin).
  const std::string gap = copyOfData(out + "/gap");
  fs::remove(gap + "/training/velodyne/0000/000012.bin");
  ChildProcess run2(runArgs(out + "/run-gap", {"--no-eval"}, gap), out + "/gap.log");
  EXPECT_EQ(run2.wait(60), 1) << run2.output();
  EXPECT_NE(run2.output().find("expected scans 000000.bin .. 000029.bin without gaps; missing 000012.bin"),
            std::string::npos)
      << run2.output();
}

TEST(RunHostileInputProcess, ASecondRunOnTheSameUrlIsRefusedAndTheFirstIsUnharmed) {
  ASSERT_TRUE(insidePrivateNetwork());
  const std::string out = scratchDir();
  ChildProcess a(runArgs(out + "/a", {"--no-render"}), out + "/a.log");
  // Wait until A plays (its SLOT_STATE is on the bus), then start B on the same URL.
  {
    lcm::LCM lcm;
    ASSERT_TRUE(lcm.good());
    bool playing = false;
    auto* sub = lcm.subscribeFunction<bool*>(
        "SLOT_STATE", [](const lcm::ReceiveBuffer*, const std::string&, bool* p) { *p = true; }, &playing);
    ASSERT_TRUE(handleUntil(lcm, [&] { return playing || !a.running(); }, 120)) << a.output();
    lcm.unsubscribe(sub);
  }
  ASSERT_TRUE(a.running()) << a.output();
  ChildProcess b(runArgs(out + "/b", {"--no-render"}), out + "/b.log");
  EXPECT_EQ(b.wait(60), 3) << b.output();
  EXPECT_NE(b.output().find("another DL-SLOT run is using the LCM URL"), std::string::npos) << b.output();
  EXPECT_FALSE(fs::exists(out + "/b/logs/odometry.log")) << "B started its pipeline";
  EXPECT_EQ(a.wait(300), 0) << a.output();
  EXPECT_NE(a.output().find("SLOT_STATE for 30 of 30 frames"), std::string::npos) << a.output();
  EXPECT_NE(a.output().find("0 frames lost"), std::string::npos) << a.output();
}

TEST(RunHostileInputProcess, StoppedNodeInRateModeIsNamedAsStalled) {
  ASSERT_TRUE(insidePrivateNetwork());
  const std::string out = scratchDir();
  // Rate mode at half speed, the default heartbeat timeout (10 s): the player is done after 6 s,
  // and the stopped odometry must be named, not killed and called unclean.
  ChildProcess run(runArgs(out + "/run", {"--speed", "0.5", "--no-render", "--no-eval"}), out + "/run.log");
  for (int i = 0; i < 600 && !fs::exists(out + "/run/logs/player.log"); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  std::this_thread::sleep_for(std::chrono::seconds(3));
  ASSERT_TRUE(run.running()) << run.output();
  const pid_t odometry = childNamed(run.pid(), "dlslot-odometry");
  ASSERT_GT(odometry, 0);
  ASSERT_EQ(kill(odometry, SIGSTOP), 0);
  const int code = run.wait(120);
  const std::string text = run.output();
  if (kill(odometry, 0) == 0) kill(odometry, SIGKILL);
  EXPECT_EQ(code, 3) << text;
  EXPECT_NE(text.find("odometry stalled: no PROCESS_STATUS (heartbeat) for 10 s"), std::string::npos) << text;
  EXPECT_NE(text.find("frames so far"), std::string::npos) << text;
  EXPECT_EQ(text.find("did not exit cleanly"), std::string::npos) << text;
}

TEST(RunHostileInputProcess, AFullDiskUnderTheLogIsSaidSo) {
  ASSERT_TRUE(insidePrivateNetwork());
  const std::string out = scratchDir() + "/run";
  fs::create_directories(out);
  // Every write to /dev/full fails with ENOSPC, as on a full disk.
  fs::create_symlink("/dev/full", out + "/run.lcmlog");
  ChildProcess run(runArgs(out, {"--no-render", "--no-eval"}), out + "/../run.log");
  EXPECT_EQ(run.wait(120), 3) << run.output();
  const std::string text = run.output();
  EXPECT_NE(text.find("lcm-logger exited with code 1"), std::string::npos) << text;
  EXPECT_NE(text.find("run.lcmlog holds"), std::string::npos) << text;
  EXPECT_NE(text.find("a full disk or a file that cannot be written"), std::string::npos) << text;
}

TEST(RunHostileInputProcess, DlslotResolvesRelativePathsAgainstTheCallersDirectory) {
  const std::string out = scratchDir();
  const std::string cmd = "cd " + out + " && DLSLOT_BUILD_DIR=" + binDir() + "/.. " + sourceDir() +
                          "/dlslot sim --scenario intersection --frames 2 --out relative/data > sim.log 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << readText(out + "/sim.log");
  EXPECT_TRUE(fs::exists(out + "/relative/data/training/velodyne/0000/000001.bin")) << readText(out + "/sim.log");
  EXPECT_FALSE(fs::exists(sourceDir() + "/relative"));
}
