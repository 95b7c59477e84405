// dlslot-sim's cost: ray casting one HDL-64E scan (64 x 2000 rays through the static grid, the
// ground and the objects) per scenario, and a whole frame (scan + labels + detections).
// Counters: points per scan, million rays per second.
#include <benchmark/benchmark.h>

#include <memory>

#include "sim/simulation.hpp"

using namespace dlslot;

namespace {

sim::Scenario scenario(const std::string& name) {
  return sim::loadScenario(std::string(DLSLOT_SOURCE_DIR) + "/config/scenarios/" + name + ".yaml");
}

const char* kNames[] = {"urban-static", "intersection", "highway", "parking-lot"};

void BM_ScanRayCasting(benchmark::State& state) {
  const std::string name = kNames[state.range(0)];
  state.SetLabel(name);
  // The scene half way through the sequence.
  sim::Simulation sim(scenario(name));
  sim::Simulation::FrameData fd;
  for (int k = 0; k <= 150; ++k) fd = sim.frame(k, 2);
  long points = 0;
  for (auto _ : state) {
    const sim::Scan s = sim::scan(sim.scenario().sensor, fd.input, static_cast<int>(state.range(1)));
    points = s.points.cols();
    benchmark::DoNotOptimize(s.points.data());
  }
  const double rays = sim::kBeams * sim.scenario().sensor.azimuth_steps;
  state.counters["points"] = static_cast<double>(points);
  state.counters["Mrays/s"] = benchmark::Counter(rays * 1e-6, benchmark::Counter::kIsIterationInvariantRate);
}

void BM_WholeFrame(benchmark::State& state) {
  const std::string name = kNames[state.range(0)];
  state.SetLabel(name);
  const sim::Scenario sc = scenario(name);
  auto sim = std::make_unique<sim::Simulation>(sc);
  int k = 0;
  for (auto _ : state) {
    if (k == sc.frames) {  // frames are made in order: start a new drive (not timed)
      state.PauseTiming();
      sim = std::make_unique<sim::Simulation>(sc);
      k = 0;
      state.ResumeTiming();
    }
    const auto fd = sim->frame(k++, 1);
    benchmark::DoNotOptimize(fd.labels.data());
  }
}

}  // namespace

BENCHMARK(BM_ScanRayCasting)->ArgsProduct({{0, 1, 2, 3}, {1, 2}})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_WholeFrame)->DenseRange(0, 3)->Unit(benchmark::kMillisecond)->Iterations(30);
BENCHMARK_MAIN();
