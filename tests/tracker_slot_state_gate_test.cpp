// The tracker's wait for SLOT_STATE of the frame associated before (slot_state_gate.hpp).
#include <gtest/gtest.h>

#include "slot_state_gate.hpp"

using dlslot::tracker::SlotStateGate;

namespace {

std::vector<int> framesOf(const std::vector<std::pair<int, char>>& out) {
  std::vector<int> f;
  for (const auto& [frame, _] : out) f.push_back(frame);
  return f;
}

TEST(SlotStateGate, EachFrameWaitsForTheSlotStateOfTheOneBefore) {
  SlotStateGate<char> gate(true, 1.0);
  int without = 0;
  gate.push(0, 'a', 0.0);
  gate.push(1, 'b', 0.0);  // frame 1 came before SLOT_STATE 0 (two frames in flight)
  EXPECT_EQ(framesOf(gate.release(0.01, &without)), std::vector<int>{0});  // the first frame waits for nothing
  EXPECT_EQ(gate.waitingFor(), 0);
  EXPECT_TRUE(gate.release(0.02, &without).empty());
  gate.slotState(0);
  gate.push(2, 'c', 0.03);
  EXPECT_EQ(framesOf(gate.release(0.03, &without)), std::vector<int>{1});  // 2 waits for SLOT_STATE 1
  gate.slotState(1);
  EXPECT_EQ(framesOf(gate.release(0.04, &without)), std::vector<int>{2});
  EXPECT_EQ(without, 0);
}

TEST(SlotStateGate, GoesOnWithoutALostSlotStateAfterTheTimeoutCounted) {
  SlotStateGate<char> gate(true, 1.0);
  int without = 0;
  gate.push(5, 'a', 0.0);
  EXPECT_EQ(framesOf(gate.release(0.0, &without)), std::vector<int>{5});
  gate.push(6, 'b', 0.1);
  gate.push(7, 'c', 0.1);
  EXPECT_TRUE(gate.release(1.0, &without).empty());  // 0.9 s waited by frame 6
  EXPECT_EQ(framesOf(gate.release(1.2, &without)), std::vector<int>{6});  // its timeout; 7 now waits for 6
  EXPECT_EQ(without, 1);
  gate.slotState(6);
  EXPECT_EQ(framesOf(gate.release(1.3, &without)), std::vector<int>{7});
  EXPECT_EQ(without, 1);
}

TEST(SlotStateGate, DisabledPassesEveryFrameAtOnceAndResetForgets) {
  SlotStateGate<char> off(false, 1.0);
  for (int f = 0; f < 3; ++f) off.push(f, 'x', 0.0);
  EXPECT_EQ(framesOf(off.release(0.0, nullptr)), (std::vector<int>{0, 1, 2}));
  SlotStateGate<char> on(true, 1.0);
  on.push(0, 'x', 0.0);
  on.release(0.0, nullptr);
  on.reset();  // the player started again
  on.push(0, 'y', 0.0);
  EXPECT_EQ(framesOf(on.release(0.0, nullptr)), std::vector<int>{0});
}

}  // namespace
