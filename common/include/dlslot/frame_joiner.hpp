// Joins two inputs of one frame (e.g. the backend's ODOMETRY and ASSOCIATIONS) by frame index.
// Frames are released in increasing order: when both parts are there, when the first part has
// waited `timeout_s` (the other is reported missing), or when a later frame is already
// complete (the stream moved on). A part arriving for a frame already released is late.
#pragma once

#include <limits>
#include <map>
#include <optional>
#include <vector>

namespace dlslot {

template <class A, class B>
class FrameJoiner {
 public:
  struct Joined {
    int frame = 0;
    std::optional<A> a;
    std::optional<B> b;
  };

  explicit FrameJoiner(double timeout_s) : timeout_s_(timeout_s) {}

  // `now` in seconds on any monotonic clock. Return false when the frame was already released.
  bool addA(int frame, A a, double now) { return add(frame, now, [&](Pending& p) { p.a = std::move(a); }); }
  bool addB(int frame, B b, double now) { return add(frame, now, [&](Pending& p) { p.b = std::move(b); }); }

  // Frames ready at `now`, oldest first.
  std::vector<Joined> release(double now) {
    int last_complete = -1;
    for (const auto& [f, p] : pending_)
      if (p.a && p.b) last_complete = f;
    std::vector<Joined> out;
    while (!pending_.empty()) {
      auto it = pending_.begin();
      const Pending& p = it->second;
      const bool ready = (p.a && p.b) || now - p.first_arrival >= timeout_s_ || it->first < last_complete;
      if (!ready) break;
      out.push_back(Joined{it->first, std::move(it->second.a), std::move(it->second.b)});
      released_ = it->first;
      pending_.erase(it);
    }
    return out;
  }

  // Everything still waiting (end of a log), oldest first.
  std::vector<Joined> flush() { return release(std::numeric_limits<double>::infinity()); }
  size_t pending() const { return pending_.size(); }
  // The newest frame released so far (-1 before the first).
  int lastReleased() const { return released_; }
  // Forgets everything (a restarted player begins again at frame 0).
  void reset() {
    pending_.clear();
    released_ = -1;
  }

 private:
  struct Pending {
    double first_arrival = 0;
    std::optional<A> a;
    std::optional<B> b;
  };
  template <class F>
  bool add(int frame, double now, F&& set) {
    if (frame <= released_) return false;
    auto [it, inserted] = pending_.try_emplace(frame);
    if (inserted) it->second.first_arrival = now;
    set(it->second);
    return true;
  }

  double timeout_s_;
  int released_ = -1;
  std::map<int, Pending> pending_;
};

}  // namespace dlslot
