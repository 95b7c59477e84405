// When a finished run may stop its processes (end_wait.hpp), on known counts: at once when every
// frame is accounted for; while frames are still being taken, however long that takes; and not
// forever for a process that has stopped taking them.
#include <gtest/gtest.h>

#include "end_wait.hpp"

using dlslot::run::EndWait;

TEST(RunEndWait, StopsAtOnceWhenEveryFrameIsAccountedFor) {
  EndWait wait(3.0);
  EXPECT_FALSE(wait.waiting(100.0, 0, 150));
}

TEST(RunEndWait, WaitsWhileAProcessIsStillTakingFrames) {
  EndWait wait(3.0);
  // A mapper five scans behind takes one every 2 s: slower than the patience would allow in total
  // (10 s), but never 3 s without progress.
  long long taken = 145;
  for (int step = 0; step < 100; ++step) {  // 0.1 s steps: one scan at 2, 4, 6 and 8 s
    if (step > 0 && step % 20 == 0) ++taken;
    ASSERT_TRUE(wait.waiting(0.1 * step, 150 - taken, taken)) << "at " << 0.1 * step << " s, " << taken << " taken";
  }
  EXPECT_FALSE(wait.waiting(10.0, 0, 150));
}

TEST(RunEndWait, GivesUpOnAProcessThatTakesNothingFor3Seconds) {
  EndWait wait(3.0);
  EXPECT_TRUE(wait.waiting(0.0, 5, 145));
  EXPECT_TRUE(wait.waiting(2.9, 5, 145));
  EXPECT_FALSE(wait.waiting(3.0, 5, 145));
}
