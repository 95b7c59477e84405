// The mapper's cost per keyframe, in CPU time of this thread (the same on an idle machine and on
// one shared with other jobs), on the real KITTI scans of ../shared/data/kitti-tracking-0000-head
// when present (else on constructed street scans):
// - BM_MapperKeyframe: decoding aside, what the keyframe thread does with one keyframe: crop, take
//   out the points inside the (grown) boxes of the frame's objects, insert the rest in the static
//   map (every scan a keyframe, as on the highway at 25 m/s);
// - BM_PlaceRecognition: what the loop thread does with every keyframe: the 0.5 m registration
//   cloud, its Scan Context and its comparison with 100 candidates (every keyframe a metre apart
//   within the 40 m search radius of a road passed again);
// - BM_LoopVerification: one verification (GICP coarse to fine between two local maps and the
//   acceptance test with its two shifted restarts), run only when a candidate is found.
// Live, all of it runs on SCHED_IDLE threads (docs/mapping.md): the cost is the mapper's, taken
// from the cores' idle time; the pipeline bench guards its CPU per frame (bench/baseline.yaml).
#include <benchmark/benchmark.h>

#include <filesystem>

#include "../tests/odometry_scene.hpp"
#include "dlslot/cpu_clock.hpp"
#include "dlslot/kitti.hpp"
#include "dlslot/timing_stats.hpp"
#include "mapper/loop_closer.hpp"
#include "mapper/loop_verifier.hpp"
#include "mapper/mapper.hpp"
#include "mapper/scan_context.hpp"

using namespace dlslot;
using namespace dlslot::mapper;

namespace {

struct Keyframe {
  PointCloud scan;
  Pose pose;
  std::vector<Box> boxes;  // world frame
};

const std::vector<Keyframe>& keyframes() {
  static const std::vector<Keyframe> all = [] {
    std::vector<Keyframe> out;
    const std::string root = std::string(DLSLOT_SOURCE_DIR) + "/../shared/data/kitti-tracking-0000-head";
    Pose T = Pose::Identity();
    if (std::filesystem::exists(root + "/training/velodyne/0000")) {
      const kitti::SequenceReader reader(root, "0000",
                                         {root + "/detections/pointrcnn_Car/0000.txt",
                                          root + "/detections/pointrcnn_Pedestrian/0000.txt"});
      for (int i = 0; i < reader.size(); ++i) {
        Frame f = reader.read(i);
        // The ego's motion does not change the cost; 1 m a frame keeps every scan a keyframe.
        T.translation().x() = i * 1.0;
        Keyframe k{std::move(f.scan), T, {}};
        for (const Box& b : f.detections) k.boxes.push_back(b.transformed(T));
        out.push_back(std::move(k));
      }
      return out;
    }
    const odometry::test::Scene street = odometry::test::street();
    for (int i = 0; i < 30; ++i, T = T * odometry::test::planarPose(1.0, 0.0, 0.01)) out.push_back({street.scan(T, 2000), T, {}});
    return out;
  }();
  return all;
}

MapperInput input(int frame, const Keyframe& k) {
  MapperInput in;
  in.frame = frame;
  in.utime = frame * 100000LL;
  in.pose = k.pose;
  in.scan = k.scan;
  for (size_t i = 0; i < k.boxes.size(); ++i) {
    TrackSnapshot t;
    t.id = static_cast<int>(i);
    t.box = k.boxes[i];
    t.dynamic = true;  // every box is taken out: the removal test's worst case
    in.tracks.push_back(t);
  }
  return in;
}

void BM_MapperKeyframe(benchmark::State& state) {
  MapperConfig config;
  config.decision_delay_frames = 0;
  config.loop.enabled = false;
  TimingStats cpu;
  double points = 0;
  for (auto _ : state) {
    Mapper mapper(config, /*threaded=*/false);
    const std::vector<Keyframe>& all = keyframes();
    for (size_t i = 0; i < all.size(); ++i) {
      MapperInput in = input(static_cast<int>(i), all[i]);
      const double t0 = threadCpuMs();
      mapper.add(std::move(in));
      cpu.add(threadCpuMs() - t0);
      points += static_cast<double>(all[i].scan.cols());
    }
    benchmark::DoNotOptimize(mapper.map().size());
  }
  state.counters["keyframe_cpu_mean_ms"] = cpu.mean();
  state.counters["keyframe_cpu_p95_ms"] = cpu.percentile(95);
  state.counters["points_per_scan"] = cpu.count() ? points / cpu.count() : 0;
}
BENCHMARK(BM_MapperKeyframe)->Unit(benchmark::kMillisecond)->Iterations(3);

void BM_PlaceRecognition(benchmark::State& state) {
  // The search compares the query with every keyframe within search_radius_m (40 m) that lies
  // min_separation_m back along the path: a road passed again, keyframes a metre apart, ~80.
  const LoopConfig loop;
  ScanContextParams p;
  p.rings = loop.rings;
  p.sectors = loop.sectors;
  p.max_radius_m = loop.max_radius_m;
  const std::vector<Keyframe>& all = keyframes();
  std::vector<ScanContext> history;
  for (int i = 0; i < 100; ++i)
    history.push_back(makeScanContext(voxelDownsample(all[i % all.size()].scan, loop.registration_voxel_m), p));
  TimingStats cpu;
  size_t i = 0;
  for (auto _ : state) {
    const double t0 = threadCpuMs();
    const PointCloud cloud = voxelDownsample(all[i++ % all.size()].scan, loop.registration_voxel_m);
    const ScanContext q = makeScanContext(cloud, p);
    double best = 2;
    for (const ScanContext& c : history) best = std::min(best, compare(q, c).distance);
    cpu.add(threadCpuMs() - t0);
    benchmark::DoNotOptimize(best);
  }
  state.counters["keyframe_cpu_mean_ms"] = cpu.mean();
  state.counters["keyframe_cpu_p95_ms"] = cpu.percentile(95);
}
BENCHMARK(BM_PlaceRecognition)->Unit(benchmark::kMillisecond);

void BM_LoopVerification(benchmark::State& state) {
  // Two keyframes 5 scans apart, the query's prior off by 0.5 m and 1 deg (a loop's drift).
  const LoopConfig loop;
  const std::vector<Keyframe>& all = keyframes();
  const Keyframe &m = all[0], &q = all[5];
  const PointCloud match = voxelDownsample(m.scan, loop.registration_voxel_m);
  const PointCloud query = voxelDownsample(q.scan, loop.registration_voxel_m);
  Pose off = Pose::Identity();
  off.translation() << 0.5, -0.3, 0;
  off.linear() = Eigen::AngleAxisd(M_PI / 180, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Pose prior = m.pose.inverse() * q.pose * off;
  TimingStats cpu;
  int accepted = 0;
  for (auto _ : state) {
    const double t0 = threadCpuMs();
    const LoopVerdict v = verifyLoop(query, match, prior, 200.0, loop);
    cpu.add(threadCpuMs() - t0);
    accepted += v.accepted;
  }
  state.counters["verification_cpu_mean_ms"] = cpu.mean();
  state.counters["accepted"] = cpu.count() ? static_cast<double>(accepted) / cpu.count() : 0;
}
BENCHMARK(BM_LoopVerification)->Unit(benchmark::kMillisecond)->Iterations(2);

}  // namespace

BENCHMARK_MAIN();
