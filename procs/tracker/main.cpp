// dlslot-tracker: sliding-window trajectory association (paper III-B, III-D) over LCM.
// Joins DETECTIONS and ODOMETRY of each scan by frame, puts the detections in the world frame
// with the best ego pose known (SLOT_STATE, else chained odometry), associates them with the
// trajectories of the window and publishes ASSOCIATIONS.
// Offline (--kitti): the same association over a sequence's files, written as KITTI tracks.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <string>

#include "dlslot/associations_t.hpp"
#include "dlslot/convert.hpp"
#include "dlslot/detections_t.hpp"
#include "dlslot/frame_joiner.hpp"
#include "dlslot/node.hpp"
#include "dlslot/odometry_t.hpp"
#include "dlslot/slot_state_t.hpp"
#include "ego_pose_chain.hpp"
#include "offline_run.hpp"
#include "slot_state_gate.hpp"
#include "tracker_config.hpp"
#include "trajectory_associator.hpp"

using namespace dlslot;
using namespace dlslot::tracker;

namespace {

std::string seconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g s", s);
  return buf;
}

// The well-formed detections of one DETECTIONS message (lidar frame).
struct DetectionFrame {
  int64_t utime = 0;
  std::vector<Box> boxes;
  std::vector<int> message_index;  // index of each box in the message
  int num_rejected = 0;            // malformed boxes left out
};
// DETECTIONS and the ODOMETRY utime of one scan, joined by frame.
using Joiner = FrameJoiner<DetectionFrame, int64_t>;
using JoinedFrame = Joiner::Joined;
int64_t utimeOf(const JoinedFrame& j) { return j.a ? j.a->utime : j.b.value_or(0); }

double secondsNow() {
  return std::chrono::duration<double>(Node::Clock::now().time_since_epoch()).count();
}

// Splits a DETECTIONS message into well-formed boxes and a count of malformed ones.
DetectionFrame toDetectionFrame(const detections_t& msg) {
  DetectionFrame d;
  d.utime = msg.utime;
  for (int i = 0; i < static_cast<int>(msg.boxes.size()); ++i) {
    if (!isValid(msg.boxes[i])) {
      ++d.num_rejected;
      continue;
    }
    d.boxes.push_back(fromMsg(msg.boxes[i]));
    d.message_index.push_back(i);
  }
  return d;
}

associations_t toMsg(const JoinedFrame& joined, const EgoPose& ego, const FrameAssociations& result) {
  associations_t m;
  m.utime = utimeOf(joined);
  m.frame = joined.frame;
  m.ego_pose = dlslot::toMsg(ego.X);
  m.ego_pose_source = poseSourceName(ego.source);
  m.num_active_tracks = result.num_active_tracks;
  m.num_rejected = joined.a ? joined.a->num_rejected : 0;
  for (const Association& a : result.associations) {
    if (a.suppressed) continue;  // its class's plausibility rules it out (counted in the status)
    association_t out;
    out.detection_index = joined.a->message_index[a.detection_index];
    out.track_id = a.track_id;
    out.initialized = a.initialized;
    out.num_observations = a.num_observations;
    out.box_lidar = dlslot::toMsg(a.box_lidar);
    out.box_world = dlslot::toMsg(a.box_world);
    out.box_lidar.id = out.box_world.id = a.track_id;
    out.has_prediction = a.predicted.has_value();
    const Eigen::Vector3d p = a.predicted.value_or(Eigen::Vector3d::Zero());
    for (int k = 0; k < 3; ++k) out.predicted[k] = p[k];
    out.is_dynamic = a.is_dynamic;
    out.displacement = a.displacement;
    out.status = static_cast<int8_t>(a.status);
    out.confidence = a.confidence;
    m.associations.push_back(out);
  }
  m.num_associations = static_cast<int32_t>(m.associations.size());
  return m;
}

struct OfflineOptions {
  std::string kitti_root, sequence, poses, tracks_out, output;
  std::vector<std::string> detections;
  double min_detection_score = -1e9, frame_period_s = 0.1;
  bool all_around = false;
};

// Associates a whole sequence from files and writes the tracks (no LCM).
int runOffline(const OfflineOptions& o, TrackerConfig config) {
  if (o.sequence.empty()) throw std::invalid_argument("--sequence SSSS is required with --kitti");
  if (o.tracks_out.empty()) throw std::invalid_argument("--tracks-out FILE is required with --kitti");
  if (!o.output.empty()) config.output = trackOutputFromName(o.output);
  const kitti::SequenceReader reader(o.kitti_root, o.sequence, o.detections, o.min_detection_score, o.frame_period_s);
  if (!reader.hasScans()) std::fprintf(stderr, "sequence %s: no scans, %d frames from its labels and detections\n",
                                       o.sequence.c_str(), reader.size());
  std::string pose_source;
  const std::vector<Pose> poses = egoPosesFor(reader, o.sequence, o.poses, &pose_source);
  std::fprintf(stderr, "%s\n", pose_source.c_str());
  const OfflineResult r = associateSequence(reader, poses, config.associator, config.output, o.all_around);
  kitti::writeTrackingLabels(o.tracks_out, r.tracks);
  std::printf("%d frames, %d detections: %d associated (%d confirmed), %d not tracked (type %d, score %d, duplicate %d); "
              "%d trajectories; %zu rows written (%s, %d outside the camera image%s); association %.3f ms mean, %.3f ms p95 a frame\n",
              reader.size(), r.detections, r.associated, r.confirmed, r.skipped.total(), r.skipped.untracked_type,
              r.skipped.below_score, r.skipped.duplicate, r.trajectories, r.tracks.size(),
              config.output == TrackOutput::All ? "all tracks" : "confirmed tracks", r.outside_image,
              o.all_around ? ", written too" : " left out", r.association_ms.mean(),
              r.association_ms.percentile(95));
  return 0;
}

int run(int argc, char** argv) {
  NodeOptions node_opts;
  OfflineOptions off;
  CommandLine cl("dlslot-tracker",
                 "Associates each scan's detections with the trajectories of a sliding window (DL-SLOT III-B).\n"
                 "Subscribes DETECTIONS, ODOMETRY, SLOT_STATE; publishes ASSOCIATIONS and PROCESS_STATUS.\n"
                 "With --kitti: offline over a sequence's files, writing KITTI tracking results (for dlslot-eval --tracks).");
  node_opts.addTo(cl);
  cl.option("--kitti", &off.kitti_root, "offline: KITTI root (tracking or odometry layout)");
  cl.option("--sequence", &off.sequence, "offline: sequence name, e.g. 0000");
  cl.repeated("--detections", &off.detections, "offline: detection file or directory");
  cl.option("--poses", &off.poses,
            "offline: ego poses, KITTI 3x4 lidar poses, a file or a directory of SSSS.txt (default: the sequence's "
            "ground truth, else identity)");
  cl.option("--tracks-out", &off.tracks_out, "offline: output file, KITTI tracking result format");
  cl.option("--min-score", &off.min_detection_score, "offline: drop detections scoring below this (default -1e9)");
  cl.option("--output", &off.output, "offline: confirmed | all (default: tracker.output of the config)");
  cl.flag("--all-around", &off.all_around,
          "offline: also write tracks outside the camera image (2-D box -1), for labels all around the scan "
          "(simulated sequences); not for the KITTI devkit");
  bool follow_slot_state = false;
  cl.flag("--follow-slot-state", &follow_slot_state,
          "associate a frame only after SLOT_STATE of the frame associated before it (or join_timeout_s): "
          "the same poses as strict lockstep when the player keeps frames in flight (dlslot-player --in-flight)");
  JoinTimeoutOption join_timeout;
  join_timeout.addTo(cl, "a frame's other input or SLOT_STATE (overrides tracker.join_timeout_s)");
  if (!cl.parse(argc, argv)) return 0;

  Channels channels;
  ConfigSection root_cfg = loadPipelineConfig(node_opts.config, channels);
  TrackerConfig cfg = TrackerConfig::read(root_cfg.section("tracker"));
  cfg.join_timeout_s = join_timeout.resolve(cfg.join_timeout_s);
  if (node_opts.check_config) return 0;
  if (!off.kitti_root.empty()) return runOffline(off, cfg);

  Node node("tracker", node_opts.lcm_url, channels);
  ProcessStatus& status = node.status();
  TrajectoryAssociator associator(cfg.associator);
  EgoPoseChain ego_poses;
  Joiner joiner(cfg.join_timeout_s);
  SlotStateGate<JoinedFrame> gate(follow_slot_state, cfg.join_timeout_s);

  auto process = [&](const JoinedFrame& joined) {
    const auto tic = Node::Clock::now();
    const std::string frame = std::to_string(joined.frame);
    if (!joined.b) {
      status.timeout(channels.odometry + " for frame " + frame + " not within " +
                     seconds(cfg.join_timeout_s) + "; ego motion predicted");
      status.count("odometry_missing");
    }
    if (!joined.a) {
      status.timeout(channels.detections + " for frame " + frame + " not within " +
                     seconds(cfg.join_timeout_s) + "; frame handled as empty");
      status.count("detections_missing");
    }
    const EgoPose ego = ego_poses.poseAt(joined.frame);
    status.count(std::string("pose_source_") + poseSourceName(ego.source));
    static const std::vector<Box> kNone;
    const std::vector<Box>& boxes = joined.a ? joined.a->boxes : kNone;
    const FrameAssociations result = associator.associate(joined.frame, utimeOf(joined) * 1e-6, ego.X, boxes);
    ego_poses.forgetBefore(joined.frame);

    for (const Association& a : result.associations) {
      if (a.new_track) status.count("tracks_started");
      if (a.initialized) status.count("associations_initialized");
    }
    status.count("tracks_ended", result.num_ended_tracks);
    status.count("associations", static_cast<int64_t>(result.associations.size()));
    // Detections not tracked, by reason (counted, never silently dropped).
    status.count("detections_untracked_type", result.skipped.untracked_type);
    status.count("detections_below_score", result.skipped.below_score);
    status.count("detections_duplicate", result.skipped.duplicate);
    // Tracks whose class the window overruled, by reason.
    status.count("tracks_relabelled_too_fast", result.class_decisions.relabelled_too_fast);
    status.count("tracks_suppressed_too_fast", result.class_decisions.suppressed_too_fast);
    status.count("tracks_suppressed_on_other_class", result.class_decisions.suppressed_on_other_class);

    associations_t msg = toMsg(joined, ego, result);
    const double ms = std::chrono::duration<double, std::milli>(Node::Clock::now() - tic).count();
    msg.timings = dlslot::toMsg(StageTimings{{"total", ms}});
    msg.num_timings = static_cast<int32_t>(msg.timings.size());
    node.publish(channels.associations, msg);
    status.frameDone(joined.frame, ms);
  };
  auto releaseReady = [&] {
    const double now = secondsNow();
    for (JoinedFrame& joined : joiner.release(now)) gate.push(joined.frame, std::move(joined), now);
    int without = 0;
    const int waited_for = gate.waitingFor();
    for (const auto& [frame, joined] : gate.release(now, &without)) process(joined);
    if (without > 0) {
      status.timeout(channels.slot_state + " for frame " + std::to_string(waited_for) + " not within " +
                     seconds(cfg.join_timeout_s) + "; associating without it");
      status.count("slot_state_missing", without);
    }
  };
  // The player's explicit start event (Node::onRestart) is the only thing that starts it over:
  // an old or repeated frame is refused before it gets here.
  node.onRestart([&](const run_event_t&) {
    associator.reset();
    joiner.reset();
    gate.reset();
    ego_poses = EgoPoseChain();
  });

  node.subscribeFrames<detections_t>(channels.detections, [&](const detections_t& msg) {
    DetectionFrame d = toDetectionFrame(msg);
    if (d.num_rejected > 0) {
      status.error(channels.detections + " frame " + std::to_string(msg.frame) + ": " +
                   std::to_string(d.num_rejected) + " malformed box(es) (NaN/inf field or size <= 0) rejected");
      status.count("rejected_detections", d.num_rejected);
    }
    if (!joiner.addA(msg.frame, std::move(d), secondsNow())) status.count("stale_messages");
    releaseReady();
  });
  node.subscribeFrames<odometry_t>(channels.odometry, [&](const odometry_t& msg) {
    if (!joiner.addB(msg.frame, msg.utime, secondsNow())) {
      status.count("stale_messages");
      return;
    }
    ego_poses.addOdometry(msg.frame, fromMsg(msg.pose), fromMsg(msg.delta));
    releaseReady();
  });
  node.subscribe<slot_state_t>(channels.slot_state, [&](const slot_state_t& msg) {
    ego_poses.addOptimized(msg.frame, fromMsg(msg.ego_pose));
    gate.slotState(msg.frame);
    releaseReady();
  });
  node.every(0.02, releaseReady);
  return node.run();
}

}  // namespace

int main(int argc, char** argv) { return runMain("dlslot-tracker", [&] { return run(argc, argv); }); }
