// Evaluator speed on a realistic run: 300 scans, 20 labelled objects and 25 tracks a scan
// (CLEAR MOT + HOTA on both matching lines, velocities), and the ego metrics of a 4500-scan
// sequence (KITTI 00 length).
#include <benchmark/benchmark.h>

#include <random>

#include "evaluation.hpp"

using namespace dlslot;
using namespace dlslot::eval;

namespace {

RunData trackingRun(int frames, int objects, int extra_tracks) {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.3);
  RunData run;
  run.has_labels = run.has_tracks = run.track_velocities_given = true;
  for (int t = 0; t < frames; ++t) {
    TrackingFrame f;
    f.frame = t;
    f.stamp = 0.1 * t;
    f.truth_pose = f.ego_pose = Pose(Eigen::Translation3d(1.0 * t, 0, 0));
    for (int k = 0; k < objects + extra_tracks; ++k) {
      Box b;
      b.center << 5.0 * k - 1.0 * t + 0.5 * t * (k % 3), 4.0 * (k % 5) - 8, 0.8;
      b.size << 4.2, 1.8, 1.6;
      b.yaw = 0.1 * k;
      b.type = "Car";
      b.id = k;
      if (k < objects) f.truth.push_back({b, std::nullopt, false});
      Box h = b;
      h.center += Eigen::Vector3d(noise(rng), noise(rng), 0);
      h.id = 1000 + k + (t > frames / 2 && k % 7 == 0 ? 500 : 0);  // some identity switches
      Object o{h, Eigen::Vector2d(0.5 * (k % 3) + noise(rng), noise(rng)), false};
      if (k % 11 != 0 || t % 4 != 0) f.tracks.push_back(o);  // some misses
    }
    run.tracking.push_back(std::move(f));
  }
  return run;
}

void BM_TrackingMetrics300Frames(benchmark::State& state) {
  const RunData run = trackingRun(300, 20, 5);
  for (auto _ : state) benchmark::DoNotOptimize(evaluate(run, EvalOptions()));
  state.counters["frames"] = 300;
}
BENCHMARK(BM_TrackingMetrics300Frames)->Unit(benchmark::kMillisecond);

void BM_EgoMetrics4500Frames(benchmark::State& state) {
  RunData run;
  Trajectory gt, est;
  double yaw = 0, x = 0, y = 0;
  for (int i = 0; i < 4500; ++i) {
    Pose T = Pose::Identity();
    T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    T.translation() << x, y, 0;
    gt.add(i, 0.1 * i, T);
    T.translation() *= 1.01;
    est.add(i, 0.1 * i, T);
    yaw += 0.01 * std::sin(0.01 * i);
    x += std::cos(yaw);
    y += std::sin(yaw);
  }
  run.sources["slot"] = est;
  run.truth = gt;
  for (auto _ : state) benchmark::DoNotOptimize(evaluate(run, EvalOptions()));
}
BENCHMARK(BM_EgoMetrics4500Frames)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
