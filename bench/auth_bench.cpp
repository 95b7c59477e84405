// What authenticating a message costs (message_auth.hpp): sealing and opening a 2 MB scan (a
// KITTI HDL-64 scan is ~120k points x 16 bytes) and a small message, against encoding the scan
// with lcm-gen (what every publish costs anyway). The budget: <= 1 ms per 2 MB scan.
#include <benchmark/benchmark.h>

#include <vector>

#include "dlslot/message_auth.hpp"
#include "dlslot/point_cloud_t.hpp"

using namespace dlslot;

namespace {

constexpr size_t kScanBytes = 2 * 1024 * 1024;

void BM_SealScan(benchmark::State& state) {
  MessageAuth tx(makeRunKey());
  const size_t n = static_cast<size_t>(state.range(0));
  std::vector<uint8_t> buf(tx.headerBytes() + n + tx.tagBytes(), 7);
  for (auto _ : state) {
    tx.seal("LIDAR_SCAN", buf.data(), n);
    benchmark::DoNotOptimize(buf.data());
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations() * n));
}
BENCHMARK(BM_SealScan)->Arg(kScanBytes)->Arg(600)->Unit(benchmark::kMillisecond);

void BM_OpenScan(benchmark::State& state) {
  const RunKey key = makeRunKey();
  MessageAuth tx(key);
  const size_t n = static_cast<size_t>(state.range(0));
  std::vector<uint8_t> payload(n, 7);
  // One sealed message per iteration would measure the seal too: seal a batch first.
  std::vector<std::vector<uint8_t>> sealed;
  for (int i = 0; i < 64; ++i) sealed.push_back(tx.sealCopy("LIDAR_SCAN", payload.data(), n));
  size_t i = 0;
  MessageAuth rx(key);
  for (auto _ : state) {
    if (i == sealed.size()) {  // a fresh receiver: the batch's sequence numbers are new to it
      state.PauseTiming();
      rx = MessageAuth(key);
      i = 0;
      state.ResumeTiming();
    }
    const uint8_t* p = nullptr;
    size_t size = 0;
    const Refusal r = rx.open("LIDAR_SCAN", sealed[i].data(), sealed[i].size(), &p, &size);
    if (r) state.SkipWithError(r.reason.c_str());
    benchmark::DoNotOptimize(p);
    ++i;
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations() * n));
}
BENCHMARK(BM_OpenScan)->Arg(kScanBytes)->Arg(600)->Unit(benchmark::kMillisecond);

// For scale: lcm-gen's encoding of a 2 MB scan, which every publish already pays.
void BM_EncodeScan(benchmark::State& state) {
  point_cloud_t m;
  m.sequence = "0000";
  m.num_points = static_cast<int32_t>(kScanBytes / 16);
  m.x.assign(m.num_points, 1.f);
  m.y.assign(m.num_points, 2.f);
  m.z.assign(m.num_points, 3.f);
  m.intensity.assign(m.num_points, 0.5f);
  std::vector<uint8_t> buf(m.getEncodedSize());
  for (auto _ : state) {
    m.encode(buf.data(), 0, static_cast<int>(buf.size()));
    benchmark::DoNotOptimize(buf.data());
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations() * buf.size()));
}
BENCHMARK(BM_EncodeScan)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
