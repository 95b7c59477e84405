// The live bridge's per-client queue: a byte budget, the oldest messages dropped (and counted)
// to make room for the newest, never the other way round.
#include <gtest/gtest.h>

#include "client_queue.hpp"

using namespace dlslot::foxglove;

namespace {

QueuedMessage msg(uint64_t t, size_t bytes) { return {1, t, std::make_shared<std::string>(bytes, 'x')}; }

TEST(ClientQueue, KeepsEverythingWithinTheBudgetInOrder) {
  ClientQueue q(100);
  for (uint64_t t = 0; t < 4; ++t) q.push(msg(t, 25));
  EXPECT_EQ(q.size(), 4u);
  EXPECT_EQ(q.bytes(), 100u);
  EXPECT_EQ(q.dropped(), 0);
  for (uint64_t t = 0; t < 4; ++t) EXPECT_EQ(q.pop().time_ns, t);
  EXPECT_TRUE(q.empty());
  EXPECT_EQ(q.bytes(), 0u);
}

TEST(ClientQueue, DropsTheOldestToFitTheNewest) {
  ClientQueue q(100);
  for (uint64_t t = 0; t < 4; ++t) q.push(msg(t, 30));  // 4 x 30 > 100: message 0 goes
  EXPECT_EQ(q.dropped(), 1);
  EXPECT_EQ(q.size(), 3u);
  q.push(msg(9, 70));  // needs 70: messages 1 and 2 go
  EXPECT_EQ(q.dropped(), 3);
  EXPECT_EQ(q.pop().time_ns, 3u);
  EXPECT_EQ(q.pop().time_ns, 9u);
}

TEST(ClientQueue, AMessageLargerThanTheBudgetGoesInAlone) {
  ClientQueue q(100);
  q.push(msg(0, 10));
  q.push(msg(1, 500));
  EXPECT_EQ(q.size(), 1u);
  EXPECT_EQ(q.dropped(), 1);
  EXPECT_EQ(q.pop().time_ns, 1u);
}

}  // namespace
