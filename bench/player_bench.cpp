// Player and transport speed: reading + encoding 2 MB scans at maximum rate, and LCM
// publish-to-receive latency of a 2 MB scan. Run inside scripts/netns-run (./dlslot bench does).
#include <benchmark/benchmark.h>
#include <lcm/lcm-cpp.hpp>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <thread>

#include "dlslot/convert.hpp"
#include "dlslot/kitti.hpp"
#include "dlslot/point_cloud_t.hpp"
#include "dlslot/timing_stats.hpp"

using namespace dlslot;

namespace {

constexpr int kPoints = 131072;  // 131072 x 16 bytes = 2 MB

PointCloud syntheticScan() {
  PointCloud scan = PointCloud::Random(4, kPoints) * 50.0f;
  return scan;
}

// Frames/s of what the player does per frame: read a .bin, convert, encode and publish.
void BM_PlayerThroughput(benchmark::State& state) {
  const std::string path = (std::filesystem::temp_directory_path() / "dlslot_bench_scan.bin").string();
  kitti::writeVelodyne(path, syntheticScan());
  lcm::LCM lcm;
  if (!lcm.good()) {
    state.SkipWithError("LCM not available");
    return;
  }
  int frame = 0;
  for (auto _ : state) {
    point_cloud_t msg;
    msg.utime = frame * 100000;
    msg.frame = frame++;
    toMsg(kitti::readVelodyne(path), msg);
    lcm.publish("BENCH_SCAN", &msg);
  }
  state.counters["frames_per_s"] = benchmark::Counter(state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_PlayerThroughput)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);

// Publish-to-receive latency of one 2 MB scan between two LCM instances (two sockets).
void BM_ScanLatency(benchmark::State& state) {
  lcm::LCM pub, sub;
  if (!pub.good() || !sub.good()) {
    state.SkipWithError("LCM not available");
    return;
  }
  std::atomic<int> received{-1};
  std::atomic<int64_t> recv_ns{0};
  struct Ctx {
    std::atomic<int>* received;
    std::atomic<int64_t>* recv_ns;
  } ctx{&received, &recv_ns};
  sub.subscribeFunction<Ctx*>(
      "BENCH_LATENCY",
      [](const lcm::ReceiveBuffer* rbuf, const std::string&, Ctx* c) {
        point_cloud_t m;
        if (m.decode(rbuf->data, 0, rbuf->data_size) < 0) return;
        c->recv_ns->store(std::chrono::steady_clock::now().time_since_epoch().count());
        c->received->store(m.frame);
      },
      &ctx);
  std::atomic<bool> stop{false};
  std::thread receiver([&] {
    while (!stop) sub.handleTimeout(20);
  });
  point_cloud_t msg;
  toMsg(syntheticScan(), msg);
  TimingStats stats;
  int frame = 0, lost = 0;
  for (auto _ : state) {
    msg.frame = frame;
    const auto t0 = std::chrono::steady_clock::now();
    pub.publish("BENCH_LATENCY", &msg);
    const auto deadline = t0 + std::chrono::milliseconds(500);
    while (received.load() != frame && std::chrono::steady_clock::now() < deadline) std::this_thread::yield();
    if (received.load() == frame)
      stats.add((recv_ns.load() - t0.time_since_epoch().count()) * 1e-6);
    else
      ++lost;
    ++frame;
    state.SetIterationTime(stats.count() ? stats.percentile(50) * 1e-3 : 0.5);
  }
  stop = true;
  receiver.join();
  state.counters["latency_mean_ms"] = stats.mean();
  state.counters["latency_p95_ms"] = stats.percentile(95);
  state.counters["lost"] = lost;
}
BENCHMARK(BM_ScanLatency)->Unit(benchmark::kMillisecond)->UseManualTime()->Iterations(100);

}  // namespace

BENCHMARK_MAIN();
