// What one live client still has to receive. The bridge must never hold the pipeline: a slow
// client (or a congested link) cannot make it wait or grow without bound, so each client's
// queue has a byte budget and, when a new message does not fit, the oldest messages are dropped
// (a live view wants the newest scan, not a backlog) and counted.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <string>

namespace dlslot::foxglove {

struct QueuedMessage {
  uint32_t subscription;                       // the client's subscription id for the channel
  uint64_t time_ns;                            // receive time, nanoseconds since the epoch
  std::shared_ptr<std::string> payload;        // shared by every client that gets it; never changed while shared
};

class ClientQueue {
 public:
  explicit ClientQueue(size_t byte_budget) : budget_(byte_budget) {}
  // Appends `m`, first dropping the oldest messages until it fits. A message larger than the
  // whole budget still goes in alone (it is the newest; everything older goes).
  void push(QueuedMessage m);
  bool empty() const { return q_.empty(); }
  QueuedMessage pop();
  size_t bytes() const { return bytes_; }
  size_t size() const { return q_.size(); }
  int64_t dropped() const { return dropped_; }

 private:
  size_t budget_, bytes_ = 0;
  std::deque<QueuedMessage> q_;
  int64_t dropped_ = 0;
};

}  // namespace dlslot::foxglove
