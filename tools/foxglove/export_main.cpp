// dlslot-export: a recorded run as an MCAP file that Foxglove opens (./dlslot export --mcap).
// Every channel of the log becomes Foxglove topics (foxglove_convert.hpp lists them); the
// counts per topic, the messages that did not decode (counted, not written) and the rate are
// printed at the end.
#include <cstdio>
#include <iostream>

#include "dlslot/heap_memory.hpp"
#include "dlslot/node.hpp"
#include "dlslot/progress.hpp"
#include "mcap_export.hpp"

using namespace dlslot;

int main(int argc, char** argv) {
  return runMain("dlslot-export", [&] {
    std::string log, mcap, config = kDefaultConfig;
    bool quiet = false;
    CommandLine cl("dlslot-export", "Writes a recorded run (LCM log) as MCAP with Foxglove's schemas (JSON).");
    cl.option("--log", &log, "the run's LCM log (e.g. OUT/run.lcmlog)");
    cl.option("--mcap", &mcap, "the MCAP file to write");
    cl.option("--config", &config, "YAML config naming the channels (default config/dlslot.yaml)");
    cl.flag("--quiet", &quiet, "no progress line");
    if (!cl.parse(argc, argv)) return 0;
    if (log.empty() || mcap.empty()) throw std::invalid_argument("--log RUN.lcmlog and --mcap OUT.mcap are required");
    Channels channels;
    loadPipelineConfig(config, channels);
    retainFreedMemory();  // a scan converted every frame (heap_memory.hpp)
    ProgressLine progress("export " + mcap + " (MB of log)", 1);
    bool sized = false;
    const auto stats = foxglove::exportMcap(log, mcap, channels, [&](int64_t done, int64_t total) {
      if (quiet) return;
      if (!sized) {
        progress = ProgressLine("export " + mcap + " (MB of log)", static_cast<int>(total >> 20) + 1);
        sized = true;
      }
      progress.update(static_cast<int>(done >> 20));
    });
    if (!quiet) progress.finish();
    std::printf("%-24s %8s\n", "topic", "messages");
    for (const auto& [topic, n] : stats.messages) std::printf("%-24s %8lld\n", topic.c_str(), static_cast<long long>(n));
    int64_t refused = 0;
    for (const auto& [what, n] : stats.refused) {
      std::fprintf(stderr, "refused (not written): %s: %lld\n", what.c_str(), static_cast<long long>(n));
      refused += n;
    }
    // One thread does all the work: frames per CPU second is its rate on one free core; the
    // wall rate also counts waiting for the disk and for other processes.
    std::printf("%lld events, %lld scans, %lld refused -> %s (%.1f MB) in %.2f s wall, %.2f s CPU: "
                "%.0f frames/s wall, %.0f frames/s of CPU (one core)\n",
                static_cast<long long>(stats.events), static_cast<long long>(stats.scans), static_cast<long long>(refused),
                mcap.c_str(), stats.bytes / 1e6, stats.wall_s, stats.cpu_s,
                stats.wall_s > 0 ? stats.scans / stats.wall_s : 0.0, stats.cpu_s > 0 ? stats.scans / stats.cpu_s : 0.0);
    return 0;
  });
}
