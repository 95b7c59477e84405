// The shared frame joiner (common/include/dlslot/frame_joiner.hpp) used by the tracker and the
// backend: release order, timeouts, overtaking, late parts and restarts.
#include <gtest/gtest.h>

#include <string>

#include "dlslot/frame_joiner.hpp"

using dlslot::FrameJoiner;

TEST(FrameJoiner, CompleteFramesAreReleasedInOrder) {
  FrameJoiner<std::string, int> j(1.0);
  EXPECT_TRUE(j.addA(0, "scan0", 0.0));
  EXPECT_TRUE(j.release(0.1).empty());  // waits for the other part
  EXPECT_TRUE(j.addB(0, 100, 0.2));
  auto out = j.release(0.2);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].frame, 0);
  EXPECT_EQ(*out[0].a, "scan0");
  EXPECT_EQ(*out[0].b, 100);
  EXPECT_FALSE(j.addB(0, 100, 0.3));  // late: already released
  EXPECT_EQ(j.lastReleased(), 0);
}

TEST(FrameJoiner, TimeoutReleasesAnIncompleteFrame) {
  FrameJoiner<std::string, int> j(1.0);
  j.addB(3, 300, 10.0);
  EXPECT_TRUE(j.release(10.9).empty());
  auto out = j.release(11.0);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_FALSE(out[0].a.has_value());
  EXPECT_TRUE(out[0].b.has_value());
  EXPECT_EQ(j.lastReleased(), 3);
}

TEST(FrameJoiner, ALaterCompleteFrameOvertakesAnIncompleteOneAndResetStartsOver) {
  FrameJoiner<std::string, int> j(5.0);
  j.addA(4, "lost", 0.0);  // its other part never comes
  j.addA(5, "scan5", 0.1);
  j.addB(5, 500, 0.2);
  auto out = j.release(0.2);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].frame, 4);
  EXPECT_FALSE(out[0].b.has_value());
  EXPECT_EQ(out[1].frame, 5);
  EXPECT_TRUE(out[1].b.has_value());
  EXPECT_FALSE(j.addA(0, "old", 1.0));  // before the last released frame
  j.reset();
  EXPECT_TRUE(j.addA(0, "restart", 1.0));
  EXPECT_EQ(j.lastReleased(), -1);
}
