// dlslot-player: plays a KITTI (tracking or odometry layout) sequence, or a folder of your own
// scans with a YAML sensor calibration (--input DIR --calib FILE, scan_folder.hpp), over LCM.
// Publishes LIDAR_SCAN, DETECTIONS (every frame, empty when none; source "files"; none with
// --no-detections, when dlslot-detector makes them) and GROUND_TRUTH (when the data set has labels
// or poses), at a rate or in lockstep with a downstream channel.
#include <cstdio>
#include <deque>
#include <functional>
#include <optional>
#include <iostream>

#include "dlslot/convert.hpp"
#include "dlslot/detections_t.hpp"
#include "dlslot/ground_truth_t.hpp"
#include "dlslot/heap_memory.hpp"
#include "dlslot/input_error.hpp"
#include "dlslot/kitti.hpp"
#include "dlslot/node.hpp"
#include "dlslot/progress.hpp"
#include "dlslot/scan_encoding.hpp"
#include "playback.hpp"
#include "scan_folder.hpp"

using namespace dlslot;

namespace {

struct PlayerConfig {
  double min_detection_score = -1e9;
  double lockstep_timeout_s = 5.0;
  double frame_period_s = 0.1;
  void read(ConfigSection s) {
    s.get("min_detection_score", min_detection_score);
    s.get("lockstep_timeout_s", lockstep_timeout_s);
    s.get("frame_period_s", frame_period_s);
    // A wait and a period are durations: <= 0 would release every frame at once (frames lost).
    if (!(lockstep_timeout_s > 0))
      throw ConfigError(s.file() + ": " + s.path() + ".lockstep_timeout_s: expected > 0 s, got " +
                        std::to_string(lockstep_timeout_s));
    if (!(frame_period_s > 0))
      throw ConfigError(s.file() + ": " + s.path() + ".frame_period_s: expected > 0 s, got " +
                        std::to_string(frame_period_s));
    s.finish();
  }
};

int run(int argc, char** argv) {
  NodeOptions node_opts;
  std::string root, sequence, lockstep, input, calib_path;
  std::vector<std::string> detections;
  double speed = 1.0, delay_s = 0.5;
  int start = 0, end = -1, in_flight = 1;
  bool quiet = false, no_detections = false;
  CommandLine cl("dlslot-player", "Plays a KITTI sequence over LCM (LIDAR_SCAN, DETECTIONS, GROUND_TRUTH).");
  cl.option("--kitti", &root, "KITTI root (holding training/ or sequences/)");
  cl.option("--sequence", &sequence, "sequence name, e.g. 0000 or 07");
  cl.option("--input", &input, "instead of --kitti: a folder of .pcd or .bin scans with times.txt (docs/data-formats.md)");
  cl.option("--calib", &calib_path, "with --input: the YAML sensor calibration");
  cl.repeated("--detections", &detections, "detection file or directory (tracking format or comma-separated)");
  cl.option("--speed", &speed, "rate mode: real time x this factor; 0 = as fast as possible (default 1)");
  cl.option("--lockstep", &lockstep, "publish frame t+1 only after CHANNEL carried frame t");
  cl.option("--in-flight", &in_flight,
            "lockstep: frames published and not yet carried by CHANNEL, at most (default 1: frame t+1 after "
            "CHANNEL carried t; 2: after it carried t-1, so the odometry of t+1 runs while the backend solves t)");
  cl.option("--start", &start, "first frame (default 0)");
  cl.option("--end", &end, "last frame, inclusive (default: last)");
  cl.option("--delay", &delay_s, "seconds to wait before the first frame, for subscribers to start (default 0.5)");
  cl.flag("--quiet", &quiet, "no progress line");
  cl.flag("--no-detections", &no_detections,
          "publish no DETECTIONS (another process detects, e.g. dlslot-detector); not with --detections");
  node_opts.addTo(cl);
  if (!cl.parse(argc, argv)) return 0;

  Channels channels;
  ConfigSection root_cfg = loadPipelineConfig(node_opts.config, channels);
  PlayerConfig cfg;
  cfg.read(root_cfg.section("player"));
  if (node_opts.check_config) return 0;
  retainFreedMemory();  // a scan read, encoded and sent every frame (heap_memory.hpp)
  if (root.empty() == input.empty()) throw std::invalid_argument("give either --kitti ROOT or --input DIR");
  if (!input.empty() && calib_path.empty()) throw std::invalid_argument("--input needs --calib FILE (the sensor's YAML)");
  if (root.empty() && sequence.empty()) sequence = "input";
  if (sequence.empty()) throw std::invalid_argument("--sequence SSSS is required");
  if (in_flight < 1) throw std::invalid_argument("--in-flight: expected an integer >= 1, got " + std::to_string(in_flight));
  if (no_detections && !detections.empty())
    throw std::invalid_argument("--no-detections and --detections exclude each other");

  // The frames to play, from either source.
  std::function<Frame(int)> readFrame;
  int num_frames = 0;
  bool has_labels = false;
  std::optional<kitti::SequenceReader> kitti_reader;
  std::optional<player::FolderReader> folder_reader;
  if (!root.empty()) {
    kitti_reader.emplace(root, sequence, detections, cfg.min_detection_score, cfg.frame_period_s);
    if (!kitti_reader->hasScans())
      throw InputError(root, 0, "sequence " + sequence + " has no scans (expected training/velodyne/" + sequence +
                                    "/): the player needs them; for tracking on detections alone use dlslot-tracker "
                                    "--kitti or ./dlslot track-eval");
    readFrame = [&](int i) { return kitti_reader->read(i); };
    num_frames = kitti_reader->size();
    has_labels = kitti_reader->hasLabels();
  } else {
    folder_reader.emplace(input, player::readSensorCalibration(calib_path), detections, cfg.min_detection_score);
    readFrame = [&](int i) { return folder_reader->read(i); };
    num_frames = folder_reader->size();
  }
  const player::FrameRange range = player::resolveRange({start, end}, num_frames);

  Node node("player", node_opts.lcm_url, channels);
  installSignalHandlers();
  node.every(1.0, [&] { node.publishStatus(); });

  // Lockstep: remember the newest frame seen on the followed channel, whatever its type. Only a
  // frame this player has already published can acknowledge one (a stray frame 10^9 must not
  // release every frame after it).
  int acked_frame = -1, published_frame = -1;
  if (!lockstep.empty())
    node.subscribeRaw(lockstep, [&](const lcm::ReceiveBuffer& rbuf) {
      const int f = frameOfEncoded(rbuf.data, rbuf.data_size);
      if (f < 0)
        node.status().refused(lockstep, {"truncated", "too short to hold a frame number"});
      else if (f > published_frame)
        node.status().refused(lockstep, {"frame_range", "frame " + std::to_string(f) + " not played yet (newest " +
                                                            std::to_string(published_frame) + ")"});
      else
        acked_frame = std::max(acked_frame, f);
    });

  node.spinUntil([] { return false; }, delay_s);
  // The explicit start (RUN_EVENT): nodes that handled frames of an earlier play start over.
  node.publishStart(range.start, sequence);
  const int total = range.end - range.start + 1;
  ProgressLine progress("play " + sequence, total);
  std::optional<player::RatePacer> pacer;
  const auto t0 = Node::Clock::now();
  int played = 0;
  std::vector<uint8_t> scan_bytes;  // LIDAR_SCAN's encoding, one buffer for the whole run
  std::deque<int> unacked;          // lockstep: frames published, not yet carried by the channel
  for (int i = range.start; i <= range.end && !signalReceived(); ++i) {
    const auto tic = Node::Clock::now();
    Frame frame = readFrame(i);
    if (lockstep.empty()) {
      if (!pacer) pacer.emplace(frame.utime, speed);
      const auto due = t0 + std::chrono::duration_cast<Node::Clock::duration>(
                                std::chrono::duration<double>(pacer->offsetSeconds(frame.utime)));
      node.spinUntil([&] { return Node::Clock::now() >= due; }, 1e9);
    }

    encodeScan(frame.scan, frame.utime, frame.index, sequence, scan_bytes);
    node.publishEncoded(channels.scan, scan_bytes.data(), scan_bytes.size());

    if (!no_detections) {
      detections_t det{};
      det.utime = frame.utime;
      det.frame = frame.index;
      det.boxes = toMsg(frame.detections);
      det.num_boxes = static_cast<int32_t>(det.boxes.size());
      det.source = "files";
      node.publish(channels.detections, det);
    }

    if (frame.gt_pose || has_labels) {
      ground_truth_t gt;
      gt.utime = frame.utime;
      gt.frame = frame.index;
      gt.has_pose = frame.gt_pose.has_value();
      gt.pose = toMsg(frame.gt_pose.value_or(Pose::Identity()));
      gt.boxes = toMsg(frame.labels);
      gt.num_boxes = static_cast<int32_t>(gt.boxes.size());
      gt.dontcare = toMsg(frame.dontcare);
      gt.num_dontcare = static_cast<int32_t>(gt.dontcare.size());
      node.publish(channels.ground_truth, gt);
    }
    published_frame = frame.index;
    node.status().frameDone(frame.index, std::chrono::duration<double, std::milli>(Node::Clock::now() - tic).count());
    ++played;

    if (!lockstep.empty()) {
      unacked.push_back(frame.index);
      // The last frame waits for every frame still in flight: the run ends when all are through.
      const size_t keep = i == range.end ? 0 : static_cast<size_t>(in_flight - 1);
      while (unacked.size() > keep && !signalReceived()) {
        const int f = unacked.front();
        unacked.pop_front();
        if (!node.spinUntil([&] { return acked_frame >= f; }, cfg.lockstep_timeout_s))
          node.status().timeout(lockstep + " did not carry frame " + std::to_string(f) + " within " +
                                std::to_string(cfg.lockstep_timeout_s) + " s; continuing");
      }
    }
    if (!quiet) progress.update(played);
  }
  if (!quiet) progress.finish(std::to_string(node.status().toMessage().timeouts) + " lockstep timeouts");
  node.publishStatus();
  return signalReceived() ? 130 : 0;
}

}  // namespace

int main(int argc, char** argv) { return runMain("dlslot-player", [&] { return run(argc, argv); }); }
