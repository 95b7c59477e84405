// Renderer speed (goal: <= 20 ms per 1000x1000 frame with 120k points, to keep up at 10 Hz).
// Prints mean and p95 per frame for drawing alone, for PNG encoding alone and for both, on a
// synthetic 120k-point HDL-64E-like scan and, when the KITTI slice is present, on a real scan.
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <filesystem>

#include "bev_renderer.hpp"
#include "dlslot/kitti.hpp"
#include "dlslot/timing_stats.hpp"
#include "render_config.hpp"

namespace {

using namespace dlslot;
using namespace dlslot::renderer;

// 64 beams x 1875 azimuths = 120000 points: flat ground 1.73 m below the sensor, walls 12 m to
// either side, ranges capped at 80 m.
PointCloud syntheticScan() {
  const int beams = 64, steps = 1875;
  PointCloud scan(4, beams * steps);
  for (int b = 0; b < beams; ++b) {
    const double elev = (2.0 - 26.9 * b / (beams - 1)) * M_PI / 180.0;
    for (int a = 0; a < steps; ++a) {
      const double az = 2.0 * M_PI * a / steps;
      double r = 80.0;
      if (elev < 0) r = std::min(r, 1.73 / std::tan(-elev));
      if (std::abs(std::sin(az)) > 1e-6) r = std::min(r, 12.0 / std::abs(std::sin(az)) / std::cos(elev));
      const double xy = r * std::cos(elev);
      scan.col(b * steps + a) << static_cast<float>(xy * std::cos(az)), static_cast<float>(xy * std::sin(az)),
          static_cast<float>(std::max(-1.73, r * std::sin(elev))), 0.5f;
    }
  }
  return scan;
}

// A busy frame: 15 detections and labels, 12 tracks with 30-frame trails, 300-frame trajectories.
RenderInput busyFrame(PointCloud scan, std::vector<Box> detections) {
  RenderInput in;
  in.frame = 299;
  in.time_s = 29.9;
  in.has_scan = true;
  in.scan = std::move(scan);
  in.has_detections = in.has_ground_truth = in.has_tracks = in.has_associations = true;
  in.has_odometry = in.odometry_filtered = true;
  in.slot_mode = "slot";
  Pose ego = Pose::Identity();
  ego.translation() = Eigen::Vector3d(299.0, 0.0, 0.0);
  in.ego_pose = ego;
  in.ego_source = "DL-SLOT";
  for (int f = 0; f < 300; ++f) {
    in.slot_path.emplace_back(f, 0.02 * f, 0);
    in.odometry_path.emplace_back(f, 0.05 * f, 0);
    in.gt_path.emplace_back(f, 0, 0);
  }
  if (detections.empty())
    for (int i = 0; i < 15; ++i) {
      Box b;
      b.center = Eigen::Vector3d(-30.0 + 5.0 * i, (i % 2 ? 4.0 : -4.0), -0.9);
      b.size = Eigen::Vector3d(4.2, 1.8, 1.6);
      b.yaw = 0.1 * i;
      b.type = "Car";
      detections.push_back(b);
    }
  in.detections = detections;
  in.gt_boxes = detections;
  for (size_t i = 0; i < detections.size() && i < 12; ++i) {
    TrackState t;
    t.id = static_cast<int>(i);
    t.type = "Car";
    t.pose = ego * detections[i].pose();
    t.size = detections[i].size;
    t.is_dynamic = i % 2 == 0;
    t.velocity = t.is_dynamic ? Eigen::Vector3d(8.0, 0.5, 0) : Eigen::Vector3d::Zero();
    for (int k = 30; k > 0; --k) t.trail.push_back(t.pose.translation() - 0.1 * k * t.velocity);
    in.tracks.push_back(t);
    in.associations.push_back({static_cast<int>(i), t.id, true, detections[i].center + Eigen::Vector3d(0.3, 0.1, 0)});
  }
  in.timings = {{"odometry", {{"features", 6.0}, {"scan_to_scan", 20.0}, {"scan_to_map", 55.0}, {"total", 84.0}}},
                {"tracker", {{"total", 2.3}}},
                {"backend", {{"solve", 12.0}, {"total", 13.5}}}};
  return in;
}

const RenderInput& syntheticFrame() {
  static const RenderInput in = busyFrame(syntheticScan(), {});
  return in;
}

std::string kittiRoot() { return std::string(DLSLOT_SOURCE_DIR) + "/../shared/data/kitti-tracking-0000-head"; }

const RenderInput& kittiFrame() {
  static const RenderInput in = [] {
    const std::string root = kittiRoot();
    kitti::SequenceReader reader(root, "0000", {root + "/detections/pointrcnn_Car"}, 0.0);
    Frame f = reader.read(20);
    return busyFrame(f.scan, f.labels);
  }();
  return in;
}

template <class F>
void timed(benchmark::State& state, F&& body) {
  TimingStats stats;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    body();
    stats.add(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  state.counters["mean_ms"] = stats.mean();
  state.counters["p95_ms"] = stats.percentile(95);
}

void renderFrame(benchmark::State& state, const RenderInput& in) {
  const ViewConfig view;  // 1000 x 1000 at 0.1 m/px, every layer
  state.counters["points"] = static_cast<double>(in.scan.cols());
  timed(state, [&] { benchmark::DoNotOptimize(renderBev(in, view).data); });
}

void encodeOnly(benchmark::State& state, const RenderInput& in) {
  const cv::Mat img = renderBev(in, ViewConfig());
  const int level = RendererConfig().png_compression;
  std::vector<uchar> buf;
  timed(state, [&] { buf = encodePng(img, level); });
  state.counters["png_kb"] = buf.size() / 1024.0;
}

void renderAndEncode(benchmark::State& state, const RenderInput& in) {
  const int level = RendererConfig().png_compression;
  timed(state, [&] { benchmark::DoNotOptimize(encodePng(renderBev(in, ViewConfig()), level).data()); });
}

void BM_RenderBev_Synthetic120k(benchmark::State& s) { renderFrame(s, syntheticFrame()); }
void BM_EncodePng_Synthetic120k(benchmark::State& s) { encodeOnly(s, syntheticFrame()); }
void BM_RenderAndEncode_Synthetic120k(benchmark::State& s) { renderAndEncode(s, syntheticFrame()); }
void BM_RenderBev_Kitti(benchmark::State& s) { renderFrame(s, kittiFrame()); }
void BM_RenderAndEncode_Kitti(benchmark::State& s) { renderAndEncode(s, kittiFrame()); }

BENCHMARK(BM_RenderBev_Synthetic120k)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_EncodePng_Synthetic120k)->Unit(benchmark::kMillisecond)->MinTime(1.0);
BENCHMARK(BM_RenderAndEncode_Synthetic120k)->Unit(benchmark::kMillisecond)->MinTime(1.0);

// The real-data benchmarks exist only when the KITTI slice is there.
const bool kKittiRegistered = [] {
  if (!std::filesystem::exists(kittiRoot() + "/training/velodyne/0000/000020.bin")) return false;
  benchmark::RegisterBenchmark("BM_RenderBev_Kitti", BM_RenderBev_Kitti)->Unit(benchmark::kMillisecond)->MinTime(2.0);
  benchmark::RegisterBenchmark("BM_RenderAndEncode_Kitti", BM_RenderAndEncode_Kitti)->Unit(benchmark::kMillisecond)->MinTime(1.0);
  return true;
}();

}  // namespace

BENCHMARK_MAIN();
