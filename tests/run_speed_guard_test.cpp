// The speed guard's rule (speed_guard.hpp) on known figures, and its reading of the files.
#include <gtest/gtest.h>

#include "speed_guard.hpp"

using namespace dlslot::run;

namespace {

SpeedFigures figures(std::map<std::string, double> cpu) {
  SpeedFigures f;
  f.cpu_ms = std::move(cpu);
  f.rate_fps = 30;
  return f;
}

TEST(SpeedGuard, FailsOnlyTheProcessMoreThan15PercentOver) {
  const SpeedFigures stored = figures({{"odometry", 20.0}, {"backend", 8.0}, {"player", 4.0}});
  // odometry +14 %, backend +20 % (the bench's slowdown hook), player 3 % cheaper.
  const SpeedVerdict v = compareSpeed(stored, figures({{"odometry", 22.8}, {"backend", 9.6}, {"player", 3.88}}));
  ASSERT_EQ(v.over, std::vector<std::string>{"backend"});
  EXPECT_NE(v.report.find("backend"), std::string::npos);
  EXPECT_NE(v.report.find("FAILED"), std::string::npos);
  EXPECT_TRUE(compareSpeed(stored, figures({{"odometry", 23.0}, {"backend", 9.2}, {"player", 4.6}})).over.empty());
}

TEST(SpeedGuard, JudgesEachProcesssMedianOverTheRuns) {
  // Three runs: the mapper's one high run (4.9 ms) does not fail it against a stored 4.0, the
  // backend slower in two of three does; a process in two runs of three counts over those two.
  SpeedFigures a = figures({{"mapper", 3.9}, {"backend", 9.5}, {"player", 2.6}});
  SpeedFigures b = figures({{"mapper", 4.9}, {"backend", 9.6}, {"player", 3.2}});
  SpeedFigures c = figures({{"mapper", 4.1}, {"backend", 8.0}});
  a.rate_fps = 40;
  b.rate_fps = 44;
  c.rate_fps = 42;
  const SpeedFigures m = medianOf({a, b, c});
  EXPECT_DOUBLE_EQ(m.cpu_ms.at("mapper"), 4.1);
  EXPECT_DOUBLE_EQ(m.cpu_ms.at("backend"), 9.5);
  EXPECT_DOUBLE_EQ(m.cpu_ms.at("player"), 2.9);
  EXPECT_DOUBLE_EQ(m.rate_fps, 42);
  const SpeedFigures stored = figures({{"mapper", 4.0}, {"backend", 8.0}, {"player", 2.7}});
  EXPECT_EQ(compareSpeed(stored, m).over, std::vector<std::string>{"backend"});
  EXPECT_EQ(compareSpeed(stored, b).over, (std::vector<std::string>{"backend", "mapper", "player"}));
}

TEST(SpeedGuard, SmallProcessesHaveTheStartUpFloor) {
  const SpeedFigures stored = figures({{"tracker", 0.8}});
  // +25 % of 0.8 ms is 0.2 ms, within a process's start-up jitter per frame.
  EXPECT_TRUE(compareSpeed(stored, figures({{"tracker", 1.0}})).over.empty());
  EXPECT_EQ(compareSpeed(stored, figures({{"tracker", 1.01}})).over, std::vector<std::string>{"tracker"});
}

TEST(SpeedGuard, AStoredProcessNotMeasuredFailsANewOneIsOnlyReported) {
  const SpeedVerdict v = compareSpeed(figures({{"backend", 8.0}, {"renderer", 27.0}}),
                                      figures({{"backend", 8.0}, {"detector", 12.0}}));
  EXPECT_EQ(v.over, std::vector<std::string>{"renderer"});
  EXPECT_NE(v.report.find("detector"), std::string::npos);
}

TEST(SpeedGuard, ReadsDlslotRunsFileAndNamesABadField) {
  const SpeedFigures f = speedFromYaml(
      YAML::Load("rate_fps: 31.5\nload: [0.8, 1.1]\ncpu_ms_per_frame:\n  player: 3.3\n  backend: 7.0\n"), "speed.yaml");
  EXPECT_DOUBLE_EQ(f.rate_fps, 31.5);
  EXPECT_DOUBLE_EQ(f.cpu_ms.at("backend"), 7.0);
  EXPECT_EQ(f.load.size(), 2u);
  try {
    speedFromYaml(YAML::Load("rate_fps: 3\ncpu_ms_per_frame: {player: fast}\n"), "bench/baseline.yaml: x");
    FAIL() << "a word for a number was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("cpu_ms_per_frame.player"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("bench/baseline.yaml"), std::string::npos) << e.what();
  }
  EXPECT_THROW(speedFromYaml(YAML::Load("rate_fps: 3\n"), "f"), std::invalid_argument);
}

}  // namespace
