// dlslot-mapper: LIDAR_SCAN + SLOT_STATE -> the static map without moving objects, loop closure
// and the loop-closed trajectory; MAP_STATE every scan, the map files on exit. Live over LCM, or
// offline from a recorded run (--offline RUN.lcmlog --out DIR).
#include <lcm/lcm-cpp.hpp>
#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <numeric>

#include "dlslot/convert.hpp"
#include "dlslot/frame_joiner.hpp"
#include "dlslot/heap_memory.hpp"
#include "dlslot/lcm_log.hpp"
#include "dlslot/message_guard.hpp"
#include "dlslot/node.hpp"
#include "dlslot/point_cloud_t.hpp"
#include "dlslot/progress.hpp"
#include "dlslot/timing_stats.hpp"
#include "mapper/map_output.hpp"
#include "mapper/mapper_messages.hpp"
#include "mapper/scan_opener.hpp"

using namespace dlslot;
using namespace dlslot::mapper;

namespace {

// A LIDAR_SCAN as it arrived (its layout checked): its points are decoded only when the scan
// becomes a keyframe, which is known once its SLOT_STATE is there. At 10 m/s and a keyframe every
// metre or two, most scans are never decoded.
struct RawScan {
  std::vector<uint8_t> bytes;
  size_t offset = 0, size = 0;  // the LCM-encoded scan within `bytes`
};
using Joiner = FrameJoiner<RawScan, MapperInput>;

// Scans that may wait for the opener before it catches up at normal priority: in lockstep one or
// two are in flight; eight (~16 MB) absorb a few busy seconds at 10 frames/s.
constexpr size_t kOpenerCapacity = 8;

// The frame index of a LIDAR_SCAN whose layout checked: after the type hash and the utime (LCM is big-endian).
int scanFrame(const uint8_t* data) {
  uint32_t v;
  std::memcpy(&v, data + 16, 4);
  return static_cast<int>(__builtin_bswap32(v));
}

// Checks a scan's layout and frame order; returns the frame, or -1 when refused (counted in `status`).
int acceptScan(const uint8_t* data, size_t size, FrameOrder& order, ProcessStatus& status, const std::string& channel,
               const std::string& where) {
  Refusal why = checkLayout(static_cast<const point_cloud_t*>(nullptr), data, size);
  const int frame = why ? -1 : scanFrame(data);
  if (!why) why = order.accept(frame);
  if (why) {
    status.refused(channel, why, where);
    return -1;
  }
  return frame;
}

// Hands a joined frame to the mapper with its scan raw: the points are decoded (and checked)
// only if the scan becomes a keyframe, and then on the mapper's keyframe thread. A keyframe whose
// points do not decode is refused (Mapper::takeRefusedScans) and no keyframe is made of it.
void feed(Mapper& mapper, Joiner::Joined& j) {
  auto raw = std::make_shared<RawScan>(std::move(*j.a));
  j.b->load_scan = [raw]() {
    point_cloud_t m;
    if (const Refusal why = decodeChecked(raw->bytes.data() + raw->offset, raw->size, &m))
      throw ScanRefused(why.reason, why.detail);
    return fromMsg(m);
  };
  mapper.add(std::move(*j.b));
}

// What the keyframe threads refused or caught since the last call, into the process status.
void reportWorkers(Mapper& mapper, ProcessStatus& status, const std::string& channel) {
  for (const ScanRefused& r : mapper.takeRefusedScans()) status.refused(channel, Refusal{r.reason, r.what()}, "keyframe: ");
  for (const std::string& e : mapper.takeErrors()) status.error(e);
}

double nowSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

void printSummary(const Mapper& mapper, const std::string& out, const std::vector<std::string>& files) {
  const std::vector<double> t = mapper.loops().timesMs();
  TimingStats loop;
  for (double ms : t) loop.add(ms);
  std::printf("mapper: %zu keyframes, map %zu voxels (%.2f m), removed %zu voxels; loops: %d accepted, %d refused\n",
              mapper.keyframes().size(), mapper.map().size(), mapper.map().voxelSize(), mapper.removed().size(),
              mapper.loops().accepted(), mapper.loops().rejected());
  std::printf("  keyframe thread: %d scans deferred (it was %zu keyframes behind at most, bound %d)\n",
              mapper.keyframesDeferred(), mapper.maxBacklog(), mapper.config().max_backlog_keyframes);
  std::printf("  per keyframe, CPU: decoding + removal + map %.2f ms mean; loop thread (clouds corrected, descriptor, search, verification, "
              "graph) %.2f ms mean, %.2f p95, %.1f max\n",
              mapper.keyframes().empty() ? 0.0 : mapper.keyframeMs() / mapper.keyframes().size(), loop.mean(),
              loop.percentile(95), loop.max());
  for (const LoopEvent& e : mapper.loops().allEvents()) {
    std::printf("  loop %d -> %d: %s (descriptor %.3f, inliers %.2f, rmse %.3f m)%s%s\n", e.query_frame, e.match_frame,
                e.verdict.accepted ? "accepted" : "refused", e.descriptor_distance, e.verdict.registration.inlier_ratio,
                e.verdict.registration.rmse_m, e.verdict.accepted ? "" : ": ", e.verdict.reason.c_str());
    // Every registration start's result: the start (the prior shifted along the query's x, y) and
    // where it ended (T_match_query's translation and yaw), so a wrong minimum can be seen.
    for (const RegistrationStart& s : e.verdict.starts) {
      const Registration& r = s.result;
      const Eigen::Vector3d t = r.T_match_query.translation();
      std::printf("    start %+.0f %+.0f m: inliers %.3f of %.2f supported, rmse %.3f m, at %.3f %.3f %.3f yaw %.3f deg%s%s\n",
                  s.shift.x(), s.shift.y(), r.inlier_ratio, r.support_ratio, r.rmse_m, t.x(), t.y(), t.z(),
                  std::atan2(r.T_match_query(1, 0), r.T_match_query(0, 0)) * 180.0 / M_PI,
                  r.converged ? "" : ", not converged", s.shift == e.verdict.start_shift ? " (kept)" : "");
    }
  }
  if (!out.empty()) {
    std::printf("  wrote to %s:", out.c_str());
    for (const std::string& f : files) std::printf(" %s", f.c_str());
    std::printf("\n");
  }
}

int runOffline(const MapperConfig& config, const Channels& channels, const std::string& in_path, const std::string& out) {
  lcm::LogFile in(in_path, "r");
  if (!in.good()) throw std::runtime_error(in_path + ": cannot open LCM log for reading");
  namespace fs = std::filesystem;
  const auto total = fs::file_size(in_path);
  Mapper mapper(config, /*threaded=*/false);
  Joiner joiner(std::numeric_limits<double>::infinity());
  ProcessStatus guard("mapper");
  LogEnvelopes envelopes(in_path);  // every event verified as it would be live (lcm_log.hpp)
  std::map<std::string, FrameOrder> order;
  ProgressLine progress("mapper " + fs::path(in_path).filename().string() + " (% of the log)", 100);
  int frames = 0, missing = 0;
  auto handle = [&](std::vector<Joiner::Joined> ready) {
    for (Joiner::Joined& j : ready) {
      if (!j.a || !j.b) {
        ++missing;
        continue;
      }
      feed(mapper, j);
      reportWorkers(mapper, guard, channels.scan);
      ++frames;
    }
  };
  int64_t index = 0;
  for (; const lcm::LogEvent* raw = nextLogEvent(in, in_path); ++index) {
    const bool scan = raw->channel == channels.scan, slot = raw->channel == channels.slot_state;
    if (!scan && !slot) continue;
    const std::string where = in_path + ": event " + std::to_string(index) + ": ";
    const lcm::LogEvent* ev = envelopes.open(*raw, guard, where);
    if (!ev) continue;
    const size_t size = static_cast<size_t>(std::max(ev->datalen, 0));
    if (scan) {
      const uint8_t* data = static_cast<const uint8_t*>(ev->data);
      const int frame = acceptScan(data, size, order[ev->channel], guard, ev->channel, where);
      if (frame >= 0) joiner.addA(frame, RawScan{std::vector<uint8_t>(data, data + size), 0, size}, 0.0);
    } else {
      slot_state_t m;
      Refusal why = decodeChecked(ev->data, size, &m);
      if (!why) why = order[ev->channel].accept(m.frame);
      if (why) guard.refused(ev->channel, why, where);
      else joiner.addB(m.frame, inputFromMsg(m), 0.0);
    }
    handle(joiner.release(0.0));
    if (index % 50 == 0)
      progress.update(static_cast<int>(100.0 * std::ftell(in.getFilePtr()) / std::max<double>(1, total)),
                      std::to_string(frames) + " scans");
  }
  handle(joiner.flush());
  mapper.finish();
  reportWorkers(mapper, guard, channels.scan);
  progress.finish(std::to_string(frames) + " scans");
  std::printf("mapper: %d scans with their SLOT_STATE, %d with one of the two missing\n", frames, missing);
  for (const auto& [what, n] : guard.refusals()) std::printf("  refused %s: %lld\n", what.c_str(), static_cast<long long>(n));
  const std::vector<std::string> files = out.empty() ? std::vector<std::string>{} : writeMapOutputs(out, mapper);
  printSummary(mapper, out, files);
  return 0;
}

int runLive(const MapperConfig& config, const Channels& channels, const NodeOptions& opts, const std::string& out) {
  Node node("mapper", opts.lcm_url, channels);
  // The mapper takes every scan off the pipeline's critical path and may lag it by design; with the
  // renderer on, in 3 of 39 runs (highway seed 1, 150 frames, lockstep, quiet machine) it fell more than
  // the pipeline's 7 scans behind and the kernel dropped datagrams. Four times the depth: ~30 scans.
  node.setReceiveBuffer(4);
  Mapper mapper(config, /*threaded=*/true);
  for (const std::string& e : mapper.priorityErrors()) node.status().warn(e + " (it runs at normal priority)");
  Joiner joiner(config.join_timeout_s);
  // Scans are opened (their MAC checked) off this thread; their layout and frame order are checked
  // here, in the order they arrived, as they come out of the opener.
  ScanOpener opener(node.auth().key(), channels.scan, /*threaded=*/true, kOpenerCapacity);
  if (const std::string e = opener.priorityError(); !e.empty()) node.status().warn(e + " (it runs at normal priority)");
  FrameOrder scan_order;
  auto takeOpened = [&] {
    for (ScanOpener::Opened& o : opener.take()) {
      if (o.refusal) {
        node.status().refused(channels.scan, o.refusal);
        continue;
      }
      const int frame = acceptScan(o.bytes.data() + o.offset, o.size, scan_order, node.status(), channels.scan, "");
      if (frame < 0) continue;
      if (!joiner.addA(frame, RawScan{std::move(o.bytes), o.offset, o.size}, nowSeconds()))
        node.status().warn("LIDAR_SCAN of frame " + std::to_string(frame) + " arrived after the frame was released");
    }
  };
  auto handleJoined = [&](Joiner::Joined& j) {
    if (!j.a) node.status().timeout("LIDAR_SCAN of frame " + std::to_string(j.frame));
    if (!j.b) node.status().timeout("SLOT_STATE of frame " + std::to_string(j.frame));
    if (!j.a || !j.b) return;
    const auto start = std::chrono::steady_clock::now();
    try {
      const Pose slot_pose = j.b->pose;
      const int64_t utime = j.b->utime;
      feed(mapper, j);
      reportWorkers(mapper, node.status(), channels.scan);
      node.publish(channels.map_state, mapStateMsg(mapper, j.frame, utime, slot_pose, mapper.loops().takeEvents()));
      node.status().frameDone(j.frame, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
      const MapperSnapshot now = mapper.snapshot();
      node.status().set("keyframes", now.keyframes);
      node.status().set("map_voxels", static_cast<int64_t>(now.map_voxels));
      node.status().set("keyframes_waiting", static_cast<int64_t>(now.backlog));
      node.status().set("keyframes_deferred", now.keyframes_deferred);
      node.status().set("loops_accepted", mapper.loops().accepted());
      node.status().set("loops_refused", mapper.loops().rejected());
    } catch (const std::exception& e) {
      node.status().error(std::string("frame ") + std::to_string(j.frame) + ": " + e.what());
    }
  };
  auto handleReady = [&] {
    takeOpened();
    for (Joiner::Joined& j : joiner.release(nowSeconds())) handleJoined(j);
  };
  // The scans sealed, to the opener (their points are decoded for keyframes only). A restart
  // forgets the frame order only after the scans that came before it are through.
  node.onRestart([&](const run_event_t&) {
    opener.wait(/*lift=*/false);
    takeOpened();
    scan_order.reset();
  });
  node.subscribeSealed(channels.scan, [&](const lcm::ReceiveBuffer& rbuf) {
    const uint8_t* data = static_cast<const uint8_t*>(rbuf.data);
    opener.post(std::vector<uint8_t>(data, data + rbuf.data_size));
  });
  node.subscribeFrames<slot_state_t>(channels.slot_state, [&](const slot_state_t& m) {
    if (!joiner.addB(m.frame, inputFromMsg(m), nowSeconds()))
      node.status().warn("SLOT_STATE of frame " + std::to_string(m.frame) + " arrived after the frame was released");
    handleReady();
  });
  node.every(0.05, handleReady);
  const int code = node.run();
  // Where the process's CPU went while the pipeline ran: the threads at normal priority (LCM's
  // receiving, joining, MAP_STATE: what competes with the pipeline) and the idle-priority ones.
  {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    const double total_ms = 1e3 * (usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
                            1e-3 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
    const double idle_ms = mapper.workerCpuMs() + opener.cpuMs();
    const double frames = std::max<double>(1, static_cast<double>(node.status().framesHandled()));
    std::printf("mapper: CPU while the pipeline ran: %.2f ms a frame at normal priority (receiving, joining, MAP_STATE; "
                "start-up included), %.2f ms a frame at idle priority (opening scans, keyframes, loop closure), %zu "
                "keyframes waiting at the end; the scan opener was %zu scans behind at most and caught up at normal "
                "priority %d times\n",
                (total_ms - idle_ms) / frames, idle_ms / frames, mapper.snapshot().backlog, opener.maxBacklog(),
                opener.catchUps());
  }
  // Stopped (SIGINT/SIGTERM): what is still waiting goes in, then the files.
  // A scan can still be with the opener when the run stops (at idle priority it waits while the
  // cores are busy elsewhere): opened now at normal priority, its frame handled and counted like any
  // other, and the status published again so the launcher's accounting sees it.
  opener.wait(/*lift=*/true);
  takeOpened();
  for (Joiner::Joined& j : joiner.flush()) handleJoined(j);
  node.publishStatus();
  mapper.finish();
  reportWorkers(mapper, node.status(), channels.scan);
  const std::vector<std::string> files = out.empty() ? std::vector<std::string>{} : writeMapOutputs(out, mapper);
  printSummary(mapper, out, files);
  return code;
}

}  // namespace

int main(int argc, char** argv) {
  return runMain("dlslot-mapper", [&] {
    NodeOptions opts;
    std::string offline_in, out, remove;
    bool no_loops = false;
    CommandLine cl("dlslot-mapper",
                   "Static map without moving objects, loop closure and a keyframe pose graph: LIDAR_SCAN + SLOT_STATE "
                   "-> MAP_STATE and, on exit, map.pcd, map_removed.pcd, map.png, trajectory_map_*.txt in --out.");
    opts.addTo(cl);
    cl.option("--offline", &offline_in, "rebuild from this recorded run (LCM log with LIDAR_SCAN and SLOT_STATE)");
    cl.option("--out", &out, "directory for the map files (written on exit; required with --offline)");
    cl.option("--remove", &remove, "dynamic (moving tracks) | movable (every track, parked vehicles too); overrides mapper.remove");
    cl.flag("--no-loops", &no_loops, "no loop closure (the map and trajectory follow SLOT_STATE)");
    JoinTimeoutOption join_timeout;
    join_timeout.addTo(cl, "a scan's SLOT_STATE, live (overrides mapper.join_timeout_s)");
    if (!cl.parse(argc, argv)) return 0;
    if (!offline_in.empty() && out.empty()) throw std::invalid_argument("--offline needs --out DIR");
    if (!remove.empty() && remove != "dynamic" && remove != "movable")
      throw std::invalid_argument("--remove: expected dynamic or movable, got '" + remove + "'");
    Channels channels;
    ConfigSection root = loadPipelineConfig(opts.config, channels);
    ConfigSection section = root.section("mapper");
    MapperConfig config = MapperConfig::read(section);
    section.finish();
    config.lidar = LidarConfig::read(root.section("lidar"));
    if (!remove.empty()) config.remove_movable = remove == "movable";
    if (no_loops) config.loop.enabled = false;
    config.join_timeout_s = join_timeout.resolve(config.join_timeout_s);
    if (opts.check_config) return 0;
    retainFreedMemory();  // a scan received every frame (heap_memory.hpp)
    if (!offline_in.empty()) return runOffline(config, channels, offline_in, out);
    return runLive(config, channels, opts, out);
  });
}
