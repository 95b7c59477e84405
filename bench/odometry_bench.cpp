// Odometry speed (goal: <= 20 ms a frame mean, p95 <= 30 ms, single-threaded, 120k-point
// HDL-64 frames): per-frame CPU time of this thread (frame_cpu_*: what the odometry costs,
// whatever else runs on the machine) and wall time (frame_wall_*), mean and p95, and the CPU split
// inside (the _* counters: OdometryResult::detail), on the real KITTI scans of
// ../shared/data/kitti-tracking-0000-head when present (else on constructed street scans), in
// A-LOAM and A-LOAM* modes. BM_PoseSolve* compares the hand-written registration solve with
// Ceres' on the same real scan-to-map correspondences (normal_equations.hpp).
#include <benchmark/benchmark.h>

#include <time.h>

#include <filesystem>
#include <map>

#include "../tests/odometry_scene.hpp"
#include "dlslot/kitti.hpp"
#include "dlslot/timing_stats.hpp"
#include "odometry/lidar_odometry.hpp"
#include "odometry/scan_to_map.hpp"

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

double threadCpuMs() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}

// One iteration = one frame through LidarOdometry::process; the sequence restarts (odometry
// reset) at its end, and the first frame of each pass, which registers nothing, is not counted.
// frame_*: the whole process() call (features, the registrations, map update, keeping the scan
// for the next); the stage (wall) and detail (CPU) counters split it.
void runPipeline(benchmark::State& state, bool filtered) {
  const std::vector<Frame>& seq = frames();
  OdometryConfig cfg;
  cfg.remove_detected_objects = filtered;
  cfg.sweep = SweepTiming{0.1, true};  // KITTI's raw scans, as the shipped config's lidar section says
  LidarOdometry odometry(cfg);
  std::map<std::string, TimingStats> stages, detail;
  TimingStats cpu;
  double points = 0;
  size_t i = 0;
  for (auto _ : state) {
    if (i % seq.size() == 0) odometry.reset();
    const Frame& frame = seq[i++ % seq.size()];
    const double c0 = threadCpuMs();
    const OdometryResult r = odometry.process(frame, true);
    const double c1 = threadCpuMs();
    if (r.status == Status::FirstFrame) continue;
    cpu.add(c1 - c0);
    for (const auto& [name, ms] : r.timings) stages[name].add(ms);
    for (const auto& [name, ms] : r.detail) detail[name].add(ms);
    points += r.num_points_in;
  }
  for (const auto& [name, stats] : detail) state.counters["_" + name + "_ms"] = stats.mean();
  state.counters["frame_cpu_mean_ms"] = cpu.mean();
  state.counters["frame_cpu_p95_ms"] = cpu.percentile(95);
  state.counters["frame_wall_mean_ms"] = stages["total"].mean();
  state.counters["frame_wall_p95_ms"] = stages["total"].percentile(95);
  state.counters["points_per_scan"] = stages["total"].count() ? points / stages["total"].count() : 0;
}

void BM_OdometryALoam(benchmark::State& state) { runPipeline(state, false); }
void BM_OdometryALoamFiltered(benchmark::State& state) { runPipeline(state, true); }
BENCHMARK(BM_OdometryALoam)->Unit(benchmark::kMillisecond)->Iterations(90)->UseRealTime();
BENCHMARK(BM_OdometryALoamFiltered)->Unit(benchmark::kMillisecond)->Iterations(90)->UseRealTime();

// Real scan-to-map correspondences: the map after the first scans, the next scan matched at
// the odometry's own pose.
struct RealMatches {
  Matches matches;
  Pose pose;
};
const RealMatches& realMatches() {
  static const RealMatches m = [] {
    const std::vector<Frame>& seq = frames();
    OdometryConfig cfg;
    LidarOdometry odometry(cfg);
    for (int i = 0; i < 5; ++i) odometry.process(seq[i], true);
    const ScanFeatures f = extractFeatures(seq[5].scan, cfg.features);
    RealMatches out;
    out.pose = odometry.process(seq[5], true).T_world_lidar;  // its features join the map too: fine
    out.matches = matchScanToMap(downsample(f.less_sharp, cfg.scan_to_map.edge_voxel_m),
                                 downsample(f.less_flat, cfg.scan_to_map.plane_voxel_m), odometry.map(), out.pose,
                                 cfg.scan_to_map);
    return out;
  }();
  return m;
}

template <PoseSolution (*Solve)(const Matches&, const Pose&, const SolverConfig&)>
void BM_PoseSolve(benchmark::State& state) {
  const RealMatches& m = realMatches();
  const SolverConfig cfg;  // the odometry's 4 iterations
  for (auto _ : state) benchmark::DoNotOptimize(Solve(m.matches, m.pose, cfg));
  state.counters["correspondences"] = static_cast<double>(m.matches.size());
}
BENCHMARK_TEMPLATE(BM_PoseSolve, solvePose)->Name("BM_PoseSolveGaussNewton")->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_PoseSolve, solvePoseCeres)->Name("BM_PoseSolveCeres")->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
