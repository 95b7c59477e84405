// dlslot-detector: geometric object detection on raw LiDAR scans, no neural network.
// Subscribes LIDAR_SCAN, publishes DETECTIONS (source "geometric") and PROCESS_STATUS: what the
// player publishes from detection files, made from the scan itself, so DL-SLOT runs on any log.
// With --kitti: the same detector offline over a sequence's files, with --eval recall and
// precision per class against its labels, with --write-detections a KITTI detection file.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>

#include "detector/detector_config.hpp"
#include "detector/geometric_detector.hpp"
#include "detector/object_class.hpp"
#include "detector/offline_eval.hpp"
#include "dlslot/convert.hpp"
#include "dlslot/detections_t.hpp"
#include "dlslot/heap_memory.hpp"
#include "dlslot/node.hpp"
#include "dlslot/point_cloud_t.hpp"

using namespace dlslot;
using namespace dlslot::detector;

namespace {

// The name DETECTIONS carries for boxes from this process.
constexpr const char* kSource = "geometric";

int runNode(const NodeOptions& node_opts, const Channels& channels, const DetectorConfig& cfg) {
  Node node("detector", node_opts.lcm_url, channels);
  ProcessStatus& status = node.status();
  node.subscribeFrames<point_cloud_t>(channels.scan, [&](const point_cloud_t& msg) {
    const auto tic = Node::Clock::now();
    detections_t out{};
    out.utime = msg.utime;
    out.frame = msg.frame;
    out.source = kSource;
    try {
      const DetectionResult r = detectObjects(fromMsg(msg), cfg);
      out.boxes = toMsg(r.boxes);
      out.timings = toMsg(r.timings);
      for (const auto& [type, count] : r.per_type) status.count("boxes_" + type, count);
      status.count("clusters", r.clusters);
    } catch (const std::exception& e) {  // one scan never takes the pipeline down: publish it empty
      status.error("frame " + std::to_string(msg.frame) + ": " + e.what() + "; published without boxes");
      out.boxes.clear();
    }
    // Receivers refuse a DETECTIONS message with a degenerate box whole (message_guard.hpp): a
    // cluster measured flat in some direction is left out here, counted, not sent.
    const size_t before = out.boxes.size();
    out.boxes.erase(std::remove_if(out.boxes.begin(), out.boxes.end(), [](const box_t& b) { return !isValid(b); }),
                    out.boxes.end());
    if (out.boxes.size() != before) status.count("degenerate_boxes", static_cast<int64_t>(before - out.boxes.size()));
    out.num_boxes = static_cast<int32_t>(out.boxes.size());
    // "total" is the whole callback (conversion included), as the other processes report it.
    const double total_ms = std::chrono::duration<double, std::milli>(Node::Clock::now() - tic).count();
    stage_timing_t total;
    total.name = "total";
    total.ms = total_ms;
    out.timings.push_back(total);
    out.num_timings = static_cast<int32_t>(out.timings.size());
    node.publish(channels.detections, out);
    status.frameDone(msg.frame, total_ms);
  });
  return node.run();
}

int run(int argc, char** argv) {
  NodeOptions node_opts;
  OfflineOptions off;
  bool eval = false;
  CommandLine cl("dlslot-detector",
                 "Geometric object detection on raw LiDAR scans: per-sector ground, range-image clusters, L-shape\n"
                 "boxes, class from size and shape. Subscribes LIDAR_SCAN; publishes DETECTIONS (source \"geometric\")\n"
                 "and PROCESS_STATUS. With --kitti: offline over a sequence's files (--eval, --write-detections).");
  node_opts.addTo(cl);
  cl.option("--kitti", &off.root, "offline: KITTI root (tracking or odometry layout)");
  cl.option("--sequence", &off.sequence, "offline: sequence name, e.g. 0000");
  cl.option("--frames", &off.frames, "offline: the first N frames only (default: all)");
  cl.flag("--eval", &eval, "offline: print recall and precision per class against the sequence's labels");
  cl.flag("--camera-view", &off.camera_view,
          "offline: count only detections in camera 2's image and ignore DontCare regions (real KITTI labels)");
  cl.option("--max-distance", &off.eval.max_distance_m, "offline: match distance, bird's-eye centres (default 2 m)");
  cl.option("--max-range", &off.eval.max_range_m, "offline: evaluate within this range of the sensor (default 40 m)");
  cl.option("--write-detections", &off.write_detections,
            "offline: write the detections to this file (KITTI tracking format + score, for --detections)");
  if (!cl.parse(argc, argv)) return 0;

  Channels channels;
  ConfigSection root_cfg = loadPipelineConfig(node_opts.config, channels);
  const DetectorConfig cfg = DetectorConfig::read(root_cfg.section("detector"));
  if (node_opts.check_config) return 0;
  retainFreedMemory();  // a scan decoded every frame (heap_memory.hpp)
  if (!off.root.empty()) {
    const OfflineResult r = runOffline(off, cfg);
    if (eval || off.write_detections.empty()) std::fputs(formatResult(r, off).c_str(), stdout);
    if (!off.write_detections.empty()) std::printf("wrote %d boxes to %s\n", r.boxes, off.write_detections.c_str());
    return 0;
  }
  return runNode(node_opts, channels, cfg);
}

}  // namespace

int main(int argc, char** argv) { return runMain("dlslot-detector", [&] { return run(argc, argv); }); }
