// A hostile peer on the bus of a running pipeline (dlslot-run on a short simulated sequence,
// lockstep, renderer on, inside the test's private network namespace). Mid-run it sends, without
// the run's key:
//   1. one DETECTIONS with a NaN box centre and frame 500 (it once became every node's newest
//      frame: the run stalled "after frame 500");
//   2. DETECTIONS with bad boxes at frames 2001-2004 (three in a row once made nodes follow the
//      new numbering: the tracker lost 26 of 30 frames);
//   3. the run's own messages of frames 0, 1 and 2 again, on every frame channel (an old log
//      played on the bus: the odometry reset 11 times and ended at the origin).
// With authentication (dlslot-run's default) none of it changes anything: trajectories and
// tracks are byte for byte those of a clean run, and every process counts every injected message
// it heard as refused. With --insecure the run still finishes with every real frame handled, and
// the injected messages are counted (refused by the content and frame-order checks).
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include "dlslot/frame_accounting.hpp"
#include "dlslot/message_auth.hpp"
#include "dlslot/node.hpp"
#include "bus_peer.hpp"
#include "message_samples.hpp"
#include "process_harness.hpp"

using namespace dlslot;
using namespace dlslot::test;
namespace fs = std::filesystem;

namespace {

constexpr int kFrames = 16;
constexpr int kInjectAt = 6;  // injected after the SLOT_STATE of this frame

// The LCM-encoded message inside an envelope (or the bytes themselves), for its frame number.
int frameOf(const Bytes& b) {
  if (isEnvelope(b.data(), b.size()))
    return frameOfEncoded(b.data() + kEnvelopeHeader, b.size() - kEnvelopeHeader - kEnvelopeTag);
  return frameOfEncoded(b.data(), b.size());
}

// DETECTIONS of `frame` with a NaN box centre.
Bytes badBoxes(int frame) {
  detections_t d = sampleDetectionsWithBox(frame);
  d.boxes[0].center[0] = std::numeric_limits<double>::quiet_NaN();
  return encode(d);
}

// Remembers the run's messages of frames 0-2; after the SLOT_STATE of kInjectAt sends cases 1-3.
struct Injector {
  std::map<std::string, std::map<int, Bytes>> seen;  // channel -> frame -> the run's bytes
  bool done = false;

  void onMessage(BusPeer& peer, const std::string& channel, const Bytes& b) {
    if (done) return;  // our own messages come back too
    const int f = frameOf(b);
    if (f >= 0 && f <= 2 && !seen[channel].count(f)) seen[channel][f] = b;
    if (channel != "SLOT_STATE" || f != kInjectAt) return;
    done = true;
    peer.send("DETECTIONS", badBoxes(500));                       // case 1
    for (int g = 2001; g <= 2004; ++g) peer.send("DETECTIONS", badBoxes(g));  // case 2
    for (const std::string& ch : kFrameChannels)                   // case 3
      for (const auto& [frame, bytes] : seen[ch]) peer.send(ch, bytes);
  }
};

struct RunResult {
  int code = -1;
  std::string text;
  std::map<std::string, int> sent;
};

RunResult runWithInjector(const std::string& data, const std::string& out, std::vector<std::string> extra,
                          bool inject) {
  Injector injector;
  BusPeer peer([&](BusPeer& p, const std::string& channel, const Bytes& b) {
    if (inject) injector.onMessage(p, channel, b);
  });
  std::vector<std::string> args = {bin("dlslot-run"), "--config", config(), "--kitti", data, "--detections",
                                   data + "/detections/sim", "--out", out, "--quiet"};
  args.insert(args.end(), extra.begin(), extra.end());
  ChildProcess run(args, out + ".log");
  RunResult r;
  r.code = peer.listenUntilExit(run);
  r.text = run.output();
  r.sent = peer.sent;
  if (inject) {
    EXPECT_TRUE(injector.done) << "the run never reached frame " << kInjectAt << "\n" << r.text;
  }
  return r;
}

int64_t refusedOn(const process_status_t& s, const std::string& channel) {
  int64_t n = 0;
  for (int i = 0; i < s.num_counters; ++i)
    if (s.counter_names[i].rfind("refused." + channel + ".", 0) == 0) n += s.counter_values[i];
  return n;
}

std::map<std::string, process_status_t> lastStatus(const std::string& log) {
  std::map<std::string, process_status_t> last;
  for (const process_status_t& s : decodeAll<process_status_t>(readLog(log)["PROCESS_STATUS"])) last[s.name] = s;
  return last;
}

// The terminal's frame table, report.md and metrics.json give the same count for every process
// and the same kernel drops.
void expectCountsAgree(const std::string& out, const std::string& text) {
  const std::string metrics = readText(out + "/metrics.json"), report = readText(out + "/report.md");
  ASSERT_FALSE(metrics.empty());
  const std::regex row(R"(^  (\w+) +(\d+) +(\d+) +(\d+) +(\d+)$)");
  int rows = 0;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    std::smatch m;
    if (!std::regex_match(line, m, row)) continue;
    const std::string p = m[1];
    if (p == "process") continue;
    ++rows;
    for (const auto& [what, value] : {std::pair<std::string, std::string>{"received", m[2]},
                                      {"handled", m[3]}, {"skipped", m[4]}, {"lost", m[5]}}) {
      const std::string key = "\"frames." + what + "." + p + "\": " + value;
      EXPECT_NE(metrics.find(key), std::string::npos) << key << "\n" << metrics;
    }
    EXPECT_NE(report.find("| " + p), std::string::npos) << p;
  }
  EXPECT_GE(rows, 4) << text;
  std::smatch drops;
  ASSERT_TRUE(std::regex_search(text, drops, std::regex(R"(kernel UDP drops (\d+))"))) << text;
  EXPECT_NE(metrics.find("\"frames.kernel_udp_drops\": " + drops[1].str()), std::string::npos) << metrics;
  EXPECT_NE(report.find("UDP datagrams dropped by the kernel: " + drops[1].str() + "."), std::string::npos) << report;
}

// Who listens to what (each counts what it refused on each).
const std::map<std::string, std::vector<std::string>> kListens = {
    {"odometry", {"LIDAR_SCAN", "DETECTIONS"}},
    {"tracker", {"DETECTIONS", "ODOMETRY"}},
    {"backend", {"ODOMETRY", "ASSOCIATIONS"}},
    {"renderer", kFrameChannels},
    {"mapper", {"LIDAR_SCAN", "SLOT_STATE"}},  // its scans are opened off LCM's thread: counted the same
    {"launcher", {"SLOT_STATE"}}};

}  // namespace

TEST(PipelineHostileProcess, WithoutTheKeyNothingChangesAndWithInsecureTheRunStillFinishes) {
  ASSERT_TRUE(insidePrivateNetwork());
  const std::string out = scratchDir();
  const std::string data = out + "/data";
  {
    ChildProcess sim({bin("dlslot-sim"), "--scenario", "intersection", "--frames", std::to_string(kFrames), "--seed",
                      "5", "--out", data},
                     out + "/sim.log");
    ASSERT_EQ(sim.wait(300), 0) << sim.output();
  }
  // A clean run, authenticated (the default).
  const RunResult clean = runWithInjector(data, out + "/clean", {}, false);
  ASSERT_EQ(clean.code, 0) << clean.text;
  EXPECT_NE(clean.text.find("authentication: run key"), std::string::npos) << clean.text;
  struct stat st {};
  ASSERT_EQ(stat((out + "/clean/run.key").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);  // the run folder keeps the key, for the owner only

  // 1-3 without the key: refused on arrival, so byte-identical outputs.
  const RunResult attacked = runWithInjector(data, out + "/attacked", {}, true);
  ASSERT_EQ(attacked.code, 0) << attacked.text;
  EXPECT_NE(attacked.text.find("0 frames lost"), std::string::npos) << attacked.text;
  int compared = 0;
  for (const auto& e : fs::directory_iterator(out + "/clean")) {
    const std::string name = e.path().filename().string();
    if (name.rfind("trajectory_", 0) != 0 && name != "tracks_kitti.txt") continue;
    EXPECT_EQ(readText(out + "/attacked/" + name), readText(e.path().string())) << name << " differs from the clean run";
    ++compared;
  }
  EXPECT_GE(compared, 4);
  EXPECT_FALSE(readText(out + "/attacked/tracks_kitti.txt").empty());
  auto last = lastStatus(out + "/attacked/run.lcmlog");
  for (const auto& [process, channels] : kListens) {
    ASSERT_TRUE(last.count(process)) << process;
    for (const std::string& ch : channels) {
      EXPECT_EQ(refusedOn(last[process], ch), attacked.sent.at(ch)) << process << " on " << ch;
      // Cases 1 and 2 carry no envelope; case 3 is the run's own bytes again.
      EXPECT_EQ(statusCounter(last[process], "refused." + ch + ".replayed"), static_cast<int64_t>(3))
          << process << " on " << ch;
    }
    EXPECT_EQ(statusCounter(last[process], "restarts"), 0) << process;
  }
  EXPECT_EQ(statusCounter(last["odometry"], "refused.DETECTIONS.unauthenticated"), 5);
  expectCountsAgree(out + "/attacked", attacked.text);

  // The same with --insecure: no envelopes, the content and frame-order checks refuse them all,
  // and every real frame is still handled.
  const RunResult open = runWithInjector(data, out + "/insecure", {"--insecure"}, true);
  ASSERT_EQ(open.code, 0) << open.text;
  EXPECT_NE(open.text.find("authentication: off (--insecure)"), std::string::npos) << open.text;
  EXPECT_FALSE(fs::exists(out + "/insecure/run.key"));
  EXPECT_NE(open.text.find("SLOT_STATE for " + std::to_string(kFrames) + " of " + std::to_string(kFrames) + " frames"),
            std::string::npos)
      << open.text;
  EXPECT_NE(open.text.find("0 frames lost"), std::string::npos) << open.text;
  last = lastStatus(out + "/insecure/run.lcmlog");
  for (const auto& [process, channels] : kListens) {
    ASSERT_TRUE(last.count(process)) << process;
    for (const std::string& ch : channels)
      EXPECT_EQ(refusedOn(last[process], ch), open.sent.at(ch)) << process << " on " << ch;
    EXPECT_EQ(statusCounter(last[process], "restarts"), 0) << process;  // old frames never reset a node
  }
  EXPECT_EQ(statusCounter(last["odometry"], "refused.DETECTIONS.non_finite"), 5);
  EXPECT_EQ(statusCounter(last["odometry"], "refused.DETECTIONS.old_frame"), 3);
  EXPECT_EQ(last["tracker"].frames_handled, static_cast<int64_t>(kFrames));
  expectCountsAgree(out + "/insecure", open.text);
  std::cout << "[ hostile ] injected per channel:";
  for (const auto& [ch, n] : attacked.sent) std::cout << " " << ch << "=" << n;
  std::cout << "; outputs identical to the clean run: " << compared << " files\n";
}
