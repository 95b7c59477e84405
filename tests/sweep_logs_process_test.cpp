// A seed sweep of the whole pipeline keeps each run's scores and drops its LCM log (330 MB per
// highway seed: 10 GB for the README's 30 seeds) unless asked to keep it for replays.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "process_harness.hpp"

using namespace dlslot::test;
namespace fs = std::filesystem;

namespace {

// Runs a one-seed, 12-frame slot sweep into out; exit 3 (a run flagged) is not a failure.
void sweep(const std::string& out, bool keep_logs) {
  std::vector<std::string> argv = {sourceDir() + "/scripts/sweep", "--scenario", "intersection", "--seeds", "2",
                                   "--mode", "slot", "--frames", "12", "--bin", binDir(), "--config", config(),
                                   "--out", out};
  if (keep_logs) argv.push_back("--keep-logs");
  ChildProcess run(argv, out + ".log");
  const int code = run.wait(600);
  if (code != 0 && code != 3) ADD_FAILURE() << "exit " << code << ": " << run.output();
}

// The sweep's table: its header and one line per seed that ran.
std::vector<std::string> tableLines(const std::string& out) {
  std::ifstream in(out + "/sweep.tsv");
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

}  // namespace

TEST(SweepLogsProcess, ARunsLogIsDroppedOnceScoredUnlessKept) {
  ASSERT_TRUE(insidePrivateNetwork());
  const std::string dir = scratchDir();
  for (const bool keep : {false, true}) {
    const std::string out = dir + (keep ? "/kept" : "/dropped");
    sweep(out, keep);
    const std::vector<std::string> lines = tableLines(out);
    ASSERT_EQ(lines.size(), 2u) << "expected a header and seed 2's row in " << out << "/sweep.tsv";
    EXPECT_EQ(lines[1].substr(0, 2), "2\t");
    EXPECT_TRUE(fs::exists(out + "/seed-2/run/metrics.json"));
    EXPECT_EQ(fs::exists(out + "/seed-2/run/run.lcmlog"), keep) << (keep ? "--keep-logs lost the log" : "log kept");
    EXPECT_FALSE(fs::exists(out + "/seed-2/data")) << "the simulated sequence is deleted after its seed";
  }
}
