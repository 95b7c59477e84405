// The tracker's order with the backend when the player keeps two frames in flight (dlslot-player
// --in-flight 2): frame t's detections are put in the world with the backend's optimized pose of
// the frame associated before it (ego_pose_chain.hpp), which in strict lockstep has always
// arrived, since the player published t only after that SLOT_STATE. With frames in flight the
// detections and odometry of t can come first; the gate holds them until that SLOT_STATE is in,
// so every association sees the same optimized poses as in strict lockstep, and the results are
// the same bytes. After timeout_s without it (the backend lost the frame) the frame goes on
// without it, counted.
#pragma once

#include <deque>
#include <utility>
#include <vector>

namespace dlslot::tracker {

template <class Frame>
class SlotStateGate {
 public:
  // enabled = false: every frame passes at once (rate mode, or strict lockstep).
  SlotStateGate(bool enabled, double timeout_s) : enabled_(enabled), timeout_s_(timeout_s) {}

  void push(int frame, Frame f, double now) {
    if (waiting_.empty()) front_since_ = now;
    waiting_.emplace_back(frame, std::move(f));
  }
  // SLOT_STATE carried `frame`.
  void slotState(int frame) { newest_slot_ = std::max(newest_slot_, frame); }

  // The frames to associate now, oldest first. `without_slot_state` counts those let through after
  // timeout_s without the SLOT_STATE they waited for.
  std::vector<std::pair<int, Frame>> release(double now, int* without_slot_state) {
    std::vector<std::pair<int, Frame>> out;
    while (!waiting_.empty()) {
      const bool have = !enabled_ || last_released_ < 0 || newest_slot_ >= last_released_;
      if (!have) {
        if (now - front_since_ < timeout_s_) break;
        if (without_slot_state) ++*without_slot_state;
      }
      last_released_ = waiting_.front().first;
      out.push_back(std::move(waiting_.front()));
      waiting_.pop_front();
      front_since_ = now;
    }
    return out;
  }

  // The frame that must have its SLOT_STATE before the next one passes (-1: none).
  int waitingFor() const { return last_released_; }
  void reset() {
    waiting_.clear();
    last_released_ = newest_slot_ = -1;
  }

 private:
  bool enabled_;
  double timeout_s_;
  std::deque<std::pair<int, Frame>> waiting_;
  double front_since_ = 0;
  int last_released_ = -1, newest_slot_ = -1;
};

}  // namespace dlslot::tracker
