// Odometry speed (issue: <= 50 ms a frame mean, p95 <= 80 ms, single-threaded, 120k-point HDL-64
// frames): per-frame time of feature extraction, scan-to-scan and scan-to-map, mean and p95,
// on the real KITTI scans of ../shared/data/kitti-tracking-0000-head when present (else on
// constructed street scans), in A-LOAM and A-LOAM* modes.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <map>

#include "../tests/odometry_scene.hpp"
#include "dlslot/kitti.hpp"
#include "dlslot/timing_stats.hpp"
#include "odometry/lidar_odometry.hpp"

using namespace dlslot;
using namespace dlslot::odometry;

namespace {

// The frames: real scans with their detections, or a constructed drive.
const std::vector<Frame>& frames() {
  static const std::vector<Frame> all = [] {
    std::vector<Frame> out;
    const std::string root = std::string(DLSLOT_SOURCE_DIR) + "/../shared/data/kitti-tracking-0000-head";
    if (std::filesystem::exists(root + "/training/velodyne/0000")) {
      const kitti::SequenceReader reader(root, "0000",
                                         {root + "/detections/pointrcnn_Car/0000.txt",
                                          root + "/detections/pointrcnn_Pedestrian/0000.txt"});
      for (int i = 0; i < reader.size(); ++i) out.push_back(reader.read(i));
      return out;
    }
    const test::Scene street = test::street();
    Pose T = Pose::Identity();
    for (int i = 0; i < 30; ++i, T = T * test::planarPose(1.0, 0.0, 0.01)) {
      Frame f;
      f.index = i;
      f.scan = street.scan(T, 2000);
      out.push_back(std::move(f));
    }
    return out;
  }();
  return all;
}

// One iteration = one frame through LidarOdometry::process; the sequence restarts (odometry
// reset) at its end, and the first frame of each pass, which registers nothing, is not counted.
void runPipeline(benchmark::State& state, bool filtered) {
  const std::vector<Frame>& seq = frames();
  OdometryConfig cfg;
  cfg.remove_detected_objects = filtered;
  LidarOdometry odometry(cfg);
  std::map<std::string, TimingStats> stages;
  TimingStats registered;  // features + scan_to_scan + scan_to_map
  double points = 0;
  size_t i = 0;
  for (auto _ : state) {
    if (i % seq.size() == 0) odometry.reset();
    const Frame& frame = seq[i++ % seq.size()];
    const OdometryResult r = odometry.process(frame, true);
    if (r.status == Status::FirstFrame) continue;
    double sum = 0;
    for (const auto& [name, ms] : r.timings) {
      stages[name].add(ms);
      if (name != "total") sum += ms;
    }
    registered.add(sum);
    points += r.num_points_in;
  }
  for (const char* name : {"features", "scan_to_scan", "scan_to_map"}) {
    state.counters[std::string(name) + "_mean_ms"] = stages[name].mean();
    state.counters[std::string(name) + "_p95_ms"] = stages[name].percentile(95);
  }
  state.counters["frame_mean_ms"] = registered.mean();
  state.counters["frame_p95_ms"] = registered.percentile(95);
  state.counters["points_per_scan"] = registered.count() ? points / registered.count() : 0;
}

void BM_OdometryALoam(benchmark::State& state) { runPipeline(state, false); }
void BM_OdometryALoamFiltered(benchmark::State& state) { runPipeline(state, true); }
BENCHMARK(BM_OdometryALoam)->Unit(benchmark::kMillisecond)->Iterations(90)->UseRealTime();
BENCHMARK(BM_OdometryALoamFiltered)->Unit(benchmark::kMillisecond)->Iterations(90)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
