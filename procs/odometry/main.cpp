// dlslot-odometry: A-LOAM-style LiDAR odometry on scans with detected objects removed (paper
// III-D). Joins LIDAR_SCAN and DETECTIONS by frame and publishes ODOMETRY and PROCESS_STATUS;
// with --offline it reads a KITTI sequence directly and writes the trajectory instead.
#include <chrono>
#include <cstdio>
#include <string>

#include "dlslot/convert.hpp"
#include "dlslot/detections_t.hpp"
#include "dlslot/frame_joiner.hpp"
#include "dlslot/heap_memory.hpp"
#include "dlslot/node.hpp"
#include "dlslot/odometry_t.hpp"
#include "dlslot/point_cloud_t.hpp"
#include "lidar_odometry.hpp"
#include "offline.hpp"

using namespace dlslot;
using namespace dlslot::odometry;

namespace {

double secondsNow() { return std::chrono::duration<double>(Node::Clock::now().time_since_epoch()).count(); }

int8_t statusCode(Status s) {
  switch (s) {
    case Status::Ok: return odometry_t::STATUS_OK;
    case Status::FallbackFewPoints: return odometry_t::STATUS_FALLBACK_FEW_POINTS;
    case Status::FallbackSolveFailed: return odometry_t::STATUS_FALLBACK_SOLVE_FAILED;
    case Status::FirstFrame: return odometry_t::STATUS_FIRST_FRAME;
  }
  return odometry_t::STATUS_FALLBACK_SOLVE_FAILED;
}

odometry_t toMsg(const OdometryResult& r, int64_t utime) {
  odometry_t m;
  m.utime = utime;
  m.frame = r.frame;
  m.status = statusCode(r.status);
  m.status_text = r.status_text;
  m.detections_used = r.detections_used;
  m.pose = dlslot::toMsg(r.T_world_lidar);
  m.delta = dlslot::toMsg(r.delta);
  dlslot::toMsg(r.covariance, m.covariance);
  m.min_eigenvalue = r.min_eigenvalue;
  m.num_points_in = r.num_points_in;
  m.num_points_removed = r.num_points_removed;
  m.num_edge = r.num_edge;
  m.num_plane = r.num_plane;
  m.num_map_edge = r.num_map_edge;
  m.num_map_plane = r.num_map_plane;
  m.residual_mean = r.residual_mean;
  m.num_correspondences = r.num_correspondences;
  m.timings = dlslot::toMsg(r.timings);
  m.num_timings = static_cast<int32_t>(m.timings.size());
  return m;
}

int runNode(const NodeOptions& node_opts, const Channels& channels, const OdometryConfig& cfg, double timeout_s) {
  Node node("odometry", node_opts.lcm_url, channels);
  ProcessStatus& status = node.status();
  LidarOdometry odometry(cfg);
  // A scan and its detections, joined by frame. In A-LOAM mode detections are not needed, so a
  // scan is released as soon as it arrives (timeout 0) and detections are not fed in.
  const bool need_detections = cfg.remove_detected_objects;
  FrameJoiner<Frame, std::vector<Box>> joiner(need_detections ? timeout_s : 0.0);
  std::fprintf(stderr, "dlslot-odometry: mode %s\n", modeName(cfg.remove_detected_objects));

  auto process = [&](Frame& frame, bool has_detections) {
    const auto tic = Node::Clock::now();
    if (need_detections && !has_detections) {
      status.timeout(channels.detections + " for frame " + std::to_string(frame.index) + " not within " +
                     std::to_string(timeout_s) + " s; ran unfiltered");
      status.count("unfiltered_frames");
    }
    OdometryResult r;
    try {
      r = odometry.process(frame, has_detections);
    } catch (const std::exception& e) {  // never take the pipeline down for one scan
      status.error("frame " + std::to_string(frame.index) + ": " + e.what() + "; odometry reset");
      odometry.reset();
      return;
    }
    if (r.status == Status::FallbackFewPoints || r.status == Status::FallbackSolveFailed) {
      status.warn("frame " + std::to_string(frame.index) + ": " + r.status_text + "; constant-velocity prediction");
      status.count("fallback_frames");
    } else if (r.degeneracy != Degeneracy::None) {  // a weak direction (degeneracy.hpp), checked or not
      status.warn("frame " + std::to_string(frame.index) + ": " + r.status_text);
      status.count(r.degeneracy == Degeneracy::Reanchored  ? "reanchored_frames"
                   : r.degeneracy == Degeneracy::Suspected ? "velocity_suspect_frames"
                                                           : "weak_direction_frames");
    } else if (!r.status_text.empty()) {  // registered again after fallbacks (fallback_motion.hpp)
      status.warn("frame " + std::to_string(frame.index) + ": " + r.status_text);
      status.count("recovered_frames");
    }
    if (need_detections && !has_detections)
      r.status_text += (r.status_text.empty() ? "" : "; ") + channels.detections + " timed out, ran unfiltered";
    node.publish(channels.odometry, toMsg(r, frame.utime));
    status.frameDone(frame.index, std::chrono::duration<double, std::milli>(Node::Clock::now() - tic).count());
  };
  auto releaseReady = [&] {
    for (auto& joined : joiner.release(secondsNow())) {
      if (!joined.a) continue;  // detections whose scan never came
      if (joined.b) joined.a->detections = std::move(*joined.b);
      process(*joined.a, joined.b.has_value());
    }
  };
  // The player's explicit start event (Node::onRestart) is the only thing that starts it over:
  // an old or repeated frame is refused before it gets here.
  node.onRestart([&](const run_event_t&) {
    joiner.reset();
    odometry.reset();
  });

  node.subscribeFrames<point_cloud_t>(channels.scan, [&](const point_cloud_t& msg) {
    Frame frame;
    frame.index = msg.frame;
    frame.utime = msg.utime;
    frame.scan = fromMsg(msg);
    if (!joiner.addA(msg.frame, std::move(frame), secondsNow())) status.count("stale_messages");
    releaseReady();
  });
  node.subscribeFrames<detections_t>(channels.detections, [&](const detections_t& msg) {
    std::vector<Box> boxes;
    int rejected = 0;
    for (const box_t& b : msg.boxes) {
      if (isValid(b))
        boxes.push_back(fromMsg(b));
      else
        ++rejected;
    }
    if (rejected > 0) {
      status.error(channels.detections + " frame " + std::to_string(msg.frame) + ": " + std::to_string(rejected) +
                   " malformed box(es) (NaN/inf field or size <= 0) ignored");
      status.count("rejected_detections", rejected);
    }
    if (need_detections && !joiner.addB(msg.frame, std::move(boxes), secondsNow())) status.count("stale_messages");
    releaseReady();
  });
  node.every(0.02, releaseReady);
  return node.run();
}

int run(int argc, char** argv) {
  NodeOptions node_opts;
  OfflineOptions offline;
  std::string mode;
  bool run_offline = false;
  CommandLine cl("dlslot-odometry",
                 "A-LOAM-style LiDAR odometry with detected-object point removal (DL-SLOT III-D).\n"
                 "Subscribes LIDAR_SCAN and DETECTIONS; publishes ODOMETRY and PROCESS_STATUS.\n"
                 "With --offline, reads a KITTI sequence and writes its trajectory (KITTI 3x4 poses).");
  cl.option("--mode", &mode, "aloam (raw scans) or aloam-filtered (A-LOAM*: detected objects removed); "
                             "overrides the config");
  cl.flag("--offline", &run_offline, "no LCM: read --kitti/--sequence, write --out");
  cl.option("--kitti", &offline.root, "offline: KITTI root (holding training/ or sequences/)");
  cl.option("--sequence", &offline.sequence, "offline: sequence name, e.g. 0000 or 07");
  cl.repeated("--detections", &offline.detections, "offline: detection file or directory");
  cl.option("--out", &offline.out, "offline: trajectory file to write");
  cl.flag("--quiet", &offline.quiet, "offline: no progress line");
  node_opts.addTo(cl);
  JoinTimeoutOption join_timeout;
  join_timeout.addTo(cl, "a scan's DETECTIONS before running unfiltered (overrides odometry.detections_timeout_s)");
  if (!cl.parse(argc, argv)) return 0;

  Channels channels;
  ConfigSection root_cfg = loadPipelineConfig(node_opts.config, channels);
  ConfigSection section = root_cfg.section("odometry");
  OdometryConfig cfg = readOdometryConfig(section);
  takeLidar(LidarConfig::read(root_cfg.section("lidar")), cfg);
  const double timeout_s = section.get<double>("detections_timeout_s");
  section.finish();
  if (!(timeout_s > 0)) throw ConfigError(node_opts.config + ": odometry.detections_timeout_s: expected > 0");
  // The offline driver reads detections as the player would publish them.
  ConfigSection player = root_cfg.section("player");
  player.get("min_detection_score", offline.min_detection_score);
  player.get("frame_period_s", offline.frame_period_s);
  if (!mode.empty()) cfg.remove_detected_objects = removesDetectedObjects(mode);
  if (node_opts.check_config) return 0;
  retainFreedMemory();  // a scan decoded every frame (heap_memory.hpp)

  if (run_offline) {
    if (offline.root.empty() || offline.sequence.empty() || offline.out.empty())
      throw std::invalid_argument("--offline needs --kitti ROOT, --sequence S and --out FILE");
    return runOffline(offline, cfg);
  }
  return runNode(node_opts, channels, cfg, join_timeout.resolve(timeout_s));
}

}  // namespace

int main(int argc, char** argv) { return runMain("dlslot-odometry", [&] { return run(argc, argv); }); }
