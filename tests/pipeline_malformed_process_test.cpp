// Every malformed case published to every node of a running pipeline
// (dlslot-run on a short simulated sequence, lockstep, renderer on, inside a private network
// namespace). Each node survives, counts every case it refused in PROCESS_STATUS by channel and
// reason, and the pipeline still finishes the sequence; then the offline readers of the recorded
// log (dlslot-eval inside dlslot-run, dlslot-backend --offline, dlslot-renderer --log) skip and
// count the same events.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include "bus_peer.hpp"
#include "dlslot/node.hpp"
#include "message_samples.hpp"
#include "dlslot/frame_accounting.hpp"
#include "process_harness.hpp"

using namespace dlslot;
using namespace dlslot::test;
namespace fs = std::filesystem;

namespace {

// The bad messages follow the real ones of frame kInjectAt; the frames after it keep the player
// playing while they arrive (a 16-frame run could end before the player read them, on a machine
// with nothing else to do).
constexpr int kFrames = 40;
constexpr int kInjectAt = 6;
constexpr int kOldFrame = 4;     // re-sent as the out-of-order case

std::vector<Malformed> operator+(std::vector<Malformed> a, const std::vector<Malformed>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

// Every malformed case for one channel, the message it stands in for being of frame `f`.
std::vector<Malformed> badMessagesFor(const std::string& channel, int f) {
  if (channel == "LIDAR_SCAN") {
    point_cloud_t nan = sampleScan(f);
    nan.x = nan.y = nan.z = nan.intensity = {1.f};
    nan.num_points = 1;
    Bytes b = encode(nan);
    putF32(b, b.size() - 16, std::numeric_limits<float>::quiet_NaN());
    return structuralVariants(encode(sampleScan(f)), kScanStringAt) + frameVariants(encode(sampleScan(f))) +
           std::vector<Malformed>{{"nan_point", b}};
  }
  if (channel == "DETECTIONS") {
    detections_t nan = sampleDetectionsWithBox(f);
    nan.boxes[0].center[0] = std::numeric_limits<double>::quiet_NaN();
    return structuralVariants(encode(sampleDetectionsWithBox(f)), kDetectionsStringAt, kDetectionsCountAt) +
           frameVariants(encode(sampleDetections(f))) + std::vector<Malformed>{{"nan_box", encode(nan)}};
  }
  if (channel == "GROUND_TRUTH") {
    const Bytes b = encode(sampleGroundTruth(f));
    return structuralVariants(b, kGroundTruthStringAt) + frameVariants(b) + std::vector<Malformed>{nanPose(b, kGroundTruthPoseAt)};
  }
  if (channel == "ODOMETRY") {
    const Bytes b = encode(sampleOdometry(f));
    return structuralVariants(b, kOdometryStringAt) + frameVariants(b) + std::vector<Malformed>{nanPose(b, kOdometryPoseAt)};
  }
  if (channel == "ASSOCIATIONS") {
    const Bytes b = encode(sampleAssociations(f));
    return structuralVariants(b, kAssociationsStringAt) + frameVariants(b) +
           std::vector<Malformed>{nanPose(b, kAssociationsPoseAt)};
  }
  if (channel == "SLOT_STATE") {
    const Bytes b = encode(sampleSlotState(f));
    return structuralVariants(b, kSlotStringAt, slotStateTimingsCountAt(b)) + frameVariants(b) +
           std::vector<Malformed>{nanPose(b, kSlotPoseAt)};
  }
  // PROCESS_STATUS
  process_status_t nan = sampleStatus();
  nan.time_mean_ms = std::numeric_limits<double>::quiet_NaN();
  return structuralVariants(encode(sampleStatus()), kStatusStringAt) + std::vector<Malformed>{{"nan_time", encode(nan)}};
}

// Listens to the pipeline; after the real message of frame kInjectAt on a channel it publishes
// that channel's malformed cases, then the real message again (duplicate) and the one of
// kOldFrame (out of order). PROCESS_STATUS gets its cases after SLOT_STATE's.
struct Injector {
  std::map<std::string, std::map<int, Bytes>> seen;
  std::set<std::string> done;

  void onMessage(BusPeer& peer, const std::string& channel, const Bytes& b) {
    if (done.count(channel)) return;  // our own messages come back too
    const int f = frameOfEncoded(b.data(), b.size());
    if (f < 0 || f > kInjectAt) return;
    seen[channel][f] = b;
    if (f != kInjectAt) return;
    done.insert(channel);
    for (const Malformed& m : badMessagesFor(channel, f)) peer.send(channel, m.bytes);
    peer.send(channel, b);
    ASSERT_TRUE(seen[channel].count(kOldFrame)) << channel;
    peer.send(channel, seen[channel][kOldFrame]);
    if (channel == "SLOT_STATE")
      for (const Malformed& m : badMessagesFor("PROCESS_STATUS", 0)) peer.send("PROCESS_STATUS", m.bytes);
  }
};

int64_t refusedOn(const process_status_t& s, const std::string& channel) {
  int64_t n = 0;
  for (int i = 0; i < s.num_counters; ++i)
    if (s.counter_names[i].rfind("refused." + channel + ".", 0) == 0) n += s.counter_values[i];
  return n;
}

// The events of a recorded channel that the guard refuses (decodeChecked, then FrameOrder):
// what an offline reader of the log must skip (the logger may have missed some of those sent).
template <class Msg>
int64_t refusedInLog(const std::vector<Bytes>& events) {
  FrameOrder order;
  int64_t n = 0;
  for (const Bytes& b : events) {
    Msg m;
    if (decodeChecked(b.data(), b.size(), &m) || order.accept(m.frame)) ++n;
  }
  return n;
}

}  // namespace

TEST(PipelineMalformedProcess, EveryNodeSurvivesCountsEveryCaseAndThePipelineFinishes) {
  ASSERT_TRUE(insidePrivateNetwork());
  const std::string out = scratchDir();
  const std::string data = out + "/data";
  {
    ChildProcess sim({bin("dlslot-sim"), "--scenario", "intersection", "--frames", std::to_string(kFrames), "--seed", "5",
                      "--out", data},
                     out + "/sim.log");
    ASSERT_EQ(sim.wait(300), 0) << sim.output();
  }
  Injector injector;
  BusPeer peer([&](BusPeer& p, const std::string& channel, const Bytes& b) { injector.onMessage(p, channel, b); });

  ChildProcess run({bin("dlslot-run"), "--config", config(), "--kitti", data, "--detections", data + "/detections/sim",
                    "--out", out + "/run", "--quiet", "--insecure"},  // the guard behind the envelope
                   out + "/run.log");
  const int code = peer.listenUntilExit(run);
  const std::string text = run.output();
  ASSERT_EQ(code, 0) << text;
  for (const std::string& ch : kFrameChannels) ASSERT_TRUE(injector.done.count(ch)) << ch << " never reached frame " << kInjectAt;

  // The pipeline finished the sequence: every frame once in SLOT_STATE, each process stopped cleanly.
  EXPECT_NE(text.find("SLOT_STATE for " + std::to_string(kFrames) + " of " + std::to_string(kFrames) + " frames"),
            std::string::npos)
      << text;
  auto events = readLog(out + "/run/run.lcmlog");
  FrameOrder order;
  std::set<int> frames;
  for (const slot_state_t& s : decodeAll<slot_state_t>(events["SLOT_STATE"]))
    if (!order.accept(s.frame)) frames.insert(s.frame);
  EXPECT_EQ(frames.size(), static_cast<size_t>(kFrames));

  // Each process counted exactly the cases it was sent on each channel it listens to.
  std::map<std::string, process_status_t> last;
  for (const process_status_t& s : decodeAll<process_status_t>(events["PROCESS_STATUS"])) last[s.name] = s;
  const auto sent = [&](const std::string& ch) { return static_cast<int64_t>(peer.sent.at(ch)); };
  const std::map<std::string, std::vector<std::string>> listens = {
      {"odometry", {"LIDAR_SCAN", "DETECTIONS"}},
      {"tracker", {"DETECTIONS", "ODOMETRY"}},
      {"backend", {"ODOMETRY", "ASSOCIATIONS"}},
      {"renderer", kFrameChannels}};
  int pairs = 0;
  for (const auto& [process, channels] : listens) {
    ASSERT_TRUE(last.count(process)) << process;
    for (const std::string& ch : channels) {
      EXPECT_EQ(refusedOn(last[process], ch), sent(ch)) << process << " on " << ch << ": " << last[process].last_warning;
      ++pairs;
    }
  }
  // The tracker takes any SLOT_STATE (older ones too, a late optimized pose is still a pose):
  // all but the duplicate and the out-of-order one are refused.
  EXPECT_EQ(refusedOn(last["tracker"], "SLOT_STATE"), sent("SLOT_STATE") - 2);
  // The player follows SLOT_STATE by its frame number only: the frames it never played are refused.
  EXPECT_GE(statusCounter(last["player"], "refused.SLOT_STATE.frame_range"), 2);
  // The launcher follows SLOT_STATE and PROCESS_STATUS.
  const int64_t launcher = sent("SLOT_STATE") + sent("PROCESS_STATUS");
  EXPECT_NE(text.find("launcher: refused " + std::to_string(launcher) + " messages"), std::string::npos) << text;
  // Each process logged each (channel, reason) once, however often it came.
  for (const std::string p : {"odometry", "tracker", "backend", "renderer", "player"}) {
    std::ifstream in(out + "/run/logs/" + p + ".log");
    std::map<std::string, int> lines;
    for (std::string line; std::getline(in, line);) {
      const auto at = line.find(": refused a message (");
      if (at != std::string::npos) ++lines[line.substr(0, line.find(':', at + 21))];
    }
    EXPECT_FALSE(lines.empty()) << p;
    for (const auto& [what, n] : lines) EXPECT_EQ(n, 1) << p << ": " << what;
  }
  // The evaluator (run by dlslot-run) skipped every bad event of the log and said so.
  EXPECT_NE(text.find("events refused and skipped"), std::string::npos) << text;
  std::cout << "[ malformed ] " << pairs + 3 << " (process, channel) pairs live; cases per channel:";
  for (const auto& [ch, n] : peer.sent) std::cout << " " << ch << "=" << n;
  std::cout << "\n";

  // Offline readers of the same log: the backend's replay and the renderer's log mode.
  ChildProcess backend({bin("dlslot-backend"), "--config", config(), "--offline", out + "/run/run.lcmlog", "--out",
                        out + "/replay.lcmlog"},
                       out + "/backend-offline.log");
  ASSERT_EQ(backend.wait(120), 0) << backend.output();
  const int64_t in_log[] = {refusedInLog<point_cloud_t>(events["LIDAR_SCAN"]), refusedInLog<detections_t>(events["DETECTIONS"]),
                            refusedInLog<ground_truth_t>(events["GROUND_TRUTH"]), refusedInLog<odometry_t>(events["ODOMETRY"]),
                            refusedInLog<associations_t>(events["ASSOCIATIONS"]), refusedInLog<slot_state_t>(events["SLOT_STATE"])};
  for (size_t i = 0; i < kFrameChannels.size(); ++i) EXPECT_GT(in_log[i], 0) << kFrameChannels[i] << ": none logged";
  // The backend reads the scans too: its cars' points are registered (backend.registration_types).
  const int64_t backend_refused = in_log[0] + in_log[3] + in_log[4];
  EXPECT_NE(backend.output().find(std::to_string(backend_refused) + " refused events"), std::string::npos)
      << backend.output();
  EXPECT_EQ(decodeAll<slot_state_t>(readLog(out + "/replay.lcmlog")["SLOT_STATE"]).size(), static_cast<size_t>(kFrames));

  ChildProcess render({bin("dlslot-renderer"), "--config", config(), "--log", out + "/run/run.lcmlog", "--out",
                       out + "/bev"},
                      out + "/render-offline.log");
  ASSERT_EQ(render.wait(300), 0) << render.output();
  EXPECT_NE(render.output().find("wrote " + std::to_string(kFrames) + " frames"), std::string::npos) << render.output();
  int64_t render_refused = 0;
  for (int64_t n : in_log) render_refused += n;
  EXPECT_NE(render.output().find(std::to_string(render_refused) + " refused"), std::string::npos) << render.output();
}
