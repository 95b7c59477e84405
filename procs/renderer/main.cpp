// dlslot-renderer: bird's-eye PNGs of a DL-SLOT run, live from LCM or offline from a recorded log.
//   dlslot-renderer --out DIR                    subscribe to the pipeline, one PNG per frame
//   dlslot-renderer --log RUN.lcmlog --out DIR   the same images from a recording
// Both write DIR/NNNNNN.png per frame and DIR/summary.png at the end.
#include <lcm/lcm-cpp.hpp>

#include <chrono>
#include <iostream>

#include "dlslot/heap_memory.hpp"
#include "dlslot/input_error.hpp"
#include "dlslot/lcm_log.hpp"
#include "dlslot/node.hpp"
#include "dlslot/progress.hpp"
#include "frame_queue.hpp"
#include "frame_writer.hpp"
#include "message_feed.hpp"
#include "render_config.hpp"
#include "run_state.hpp"

namespace {

using namespace dlslot;
using namespace dlslot::renderer;
using Clock = std::chrono::steady_clock;

// Hands frames to the writer thread as RunState releases them and keeps the status counters.
class FrameSink {
 public:
  FrameSink(FrameWriter& writer, ProcessStatus& status, bool skip_when_behind)
      : queue_(writer, kMaxQueued, skip_when_behind), status_(status) {}
  void draw(std::vector<RenderInput> frames) {
    for (RenderInput& in : frames)
      if (!queue_.submit(std::move(in))) status_.count("frames_skipped");
    collect();
  }
  // Counts the frames written since the last call (the status is this thread's only).
  void collect() {
    for (const FrameQueue::Written& w : queue_.takeWritten()) {
      status_.frameDone(w.frame, w.ms);
      if (!w.has_tracks) status_.count("frames_without_slot_state");
      ++written_;
    }
  }
  // Waits for every queued frame.
  void finish() {
    queue_.finish();
    collect();
  }
  int written() const { return written_; }
  int skipped() const { return queue_.skipped(); }

 private:
  // Frames waiting for the writer before newer ones are skipped (when skipping is allowed).
  static constexpr int kMaxQueued = 2;
  FrameQueue queue_;
  ProcessStatus& status_;
  int written_ = 0;
};

void report(const FrameSink& sink, const std::string& out, const std::string& summary, const ProcessStatus& status) {
  const process_status_t s = status.toMessage();
  std::cerr << "dlslot-renderer: wrote " << sink.written() << " frames to " << out << " (render+write mean "
            << s.time_mean_ms << " ms, p95 " << s.time_p95_ms << " ms, on the writer thread)";
  if (sink.skipped()) std::cerr << ", " << sink.skipped() << " frames skipped (the writer was behind)";
  if (!summary.empty()) std::cerr << ", summary " << summary;
  if (s.decode_errors) std::cerr << ", " << s.decode_errors << " undecodable messages";
  int64_t refused = 0;
  for (const auto& [what, n] : status.refusals()) refused += n;
  if (refused) std::cerr << ", " << refused << " refused messages";
  std::cerr << "\n";
}

int renderLog(const std::string& log_path, const std::string& out, const RendererConfig& cfg, const Channels& channels) {
  int scans = 0;
  {
    // A first pass counts the scans so progress can show an ETA.
    lcm::LogFile log(log_path, "r");
    if (!log.good()) throw InputError(log_path, 0, "cannot open as an LCM log");
    while (const lcm::LogEvent* e = nextLogEvent(log, log_path)) scans += e->channel == channels.scan;
  }
  lcm::LogFile log(log_path, "r");
  if (!log.good()) throw InputError(log_path, 0, "cannot open as an LCM log");
  ProcessStatus status("renderer");
  RunState state(cfg.max_pending_frames, cfg.trail_frames);
  MessageFeed feed(state, status, channels);
  FrameWriter writer(out, cfg);
  FrameSink sink(writer, status, false);
  ProgressLine progress("render", scans);
  LogEnvelopes envelopes(log_path);
  for (int64_t index = 0; const lcm::LogEvent* raw = nextLogEvent(log, log_path); ++index) {
    const lcm::LogEvent* e = envelopes.open(*raw, status, log_path + ": event " + std::to_string(index) + ": ");
    if (!e) continue;
    feed.handle(e->channel, e->data, e->datalen);
    sink.draw(state.takeReady());
    progress.update(sink.written());
  }
  sink.draw(state.takeAll());
  sink.finish();
  const std::string summary = writer.writeSummary(state.summary());
  progress.update(sink.written());
  progress.finish();
  report(sink, out, summary, status);
  return 0;
}

int renderLive(const NodeOptions& opts, const std::string& out, const RendererConfig& cfg, const Channels& channels,
               bool skip_when_behind) {
  Node node("renderer", opts.lcm_url, channels);
  RunState state(cfg.max_pending_frames, cfg.trail_frames);
  MessageFeed feed(state, node.status(), channels);
  FrameWriter writer(out, cfg);
  FrameSink sink(writer, node.status(), skip_when_behind);
  auto last_message = Clock::now();

  auto on = [&](auto handler) {
    return [&, handler](const auto& msg) {
      (feed.*handler)(msg);
      last_message = Clock::now();
      sink.draw(state.takeReady());
    };
  };
  node.subscribeFrames<point_cloud_t>(channels.scan, on(&MessageFeed::onScan));
  node.subscribeFrames<detections_t>(channels.detections, on(&MessageFeed::onDetections));
  node.subscribeFrames<ground_truth_t>(channels.ground_truth, on(&MessageFeed::onGroundTruth));
  node.subscribeFrames<odometry_t>(channels.odometry, on(&MessageFeed::onOdometry));
  node.subscribeFrames<associations_t>(channels.associations, on(&MessageFeed::onAssociations));
  node.subscribeFrames<slot_state_t>(channels.slot_state, on(&MessageFeed::onSlotState));
  // Nothing new for a while: draw what is there (the last frame of a run, a stalled pipeline).
  node.every(0.05, [&] {
    sink.collect();
    if (!state.hasPending() ||
        std::chrono::duration<double>(Clock::now() - last_message).count() < cfg.frame_timeout_s)
      return;
    std::vector<RenderInput> frames = state.takeAll();
    for (const RenderInput& in : frames)
      if (!in.has_tracks) node.status().timeout("frame " + std::to_string(in.frame) + " drawn without SLOT_STATE");
    sink.draw(std::move(frames));
  });
  const int rc = node.run();
  sink.draw(state.takeAll());
  sink.finish();
  node.publishStatus();  // the frames written after the loop ended count too
  const std::string summary = writer.writeSummary(state.summary());
  report(sink, out, summary, node.status());
  return rc;
}

}  // namespace

int main(int argc, char** argv) {
  return runMain("dlslot-renderer", [&] {
    NodeOptions opts;
    std::string out, log;
    bool skip_when_behind = false;
    CommandLine cl("dlslot-renderer",
                   "Writes a bird's-eye PNG per frame (OUT/NNNNNN.png) and a run summary (OUT/summary.png),\n"
                   "live from LCM or, with --log, from a recorded LCM log.");
    opts.addTo(cl);
    cl.option("--out", &out, "output directory for the images (required)");
    cl.option("--log", &log, "render a recorded LCM log instead of live traffic");
    cl.flag("--skip-when-behind", &skip_when_behind,
            "live: skip (and count) frames that arrive while the writer is behind (rate mode); "
            "default: every frame is written, late if need be (lockstep)");
    if (!cl.parse(argc, argv)) return 0;
    Channels channels;
    ConfigSection root = loadPipelineConfig(opts.config, channels);
    const RendererConfig cfg = readRendererConfig(root);
    if (opts.check_config) {
      std::cout << opts.config << ": renderer config OK\n";
      return 0;
    }
    if (out.empty()) throw std::invalid_argument("--out DIR is required (see --help)");
    retainFreedMemory();  // a scan decoded every frame (heap_memory.hpp)
    return log.empty() ? renderLive(opts, out, cfg, channels, skip_when_behind) : renderLog(log, out, cfg, channels);
  });
}
