#include "client_queue.hpp"

namespace dlslot::foxglove {

void ClientQueue::push(QueuedMessage m) {
  const size_t n = m.payload ? m.payload->size() : 0;
  while (!q_.empty() && bytes_ + n > budget_) {
    bytes_ -= q_.front().payload ? q_.front().payload->size() : 0;
    q_.pop_front();
    ++dropped_;
  }
  bytes_ += n;
  q_.push_back(std::move(m));
}

QueuedMessage ClientQueue::pop() {
  QueuedMessage m = std::move(q_.front());
  q_.pop_front();
  bytes_ -= m.payload ? m.payload->size() : 0;
  return m;
}

}  // namespace dlslot::foxglove
