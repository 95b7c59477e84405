#include "mapper/scan_opener.hpp"

namespace dlslot::mapper {

namespace {
MessageAuth authFor(const std::optional<RunKey>& key) { return key ? MessageAuth(*key) : MessageAuth(); }
}  // namespace

ScanOpener::ScanOpener(const std::optional<RunKey>& key, std::string channel, bool threaded, size_t capacity)
    : auth_(authFor(key)),
      channel_(std::move(channel)),
      capacity_(capacity),
      worker_("scan opener", threaded, capacity, /*idle_priority=*/true) {}

void ScanOpener::post(std::vector<uint8_t> bytes) {
  {
    std::lock_guard<std::mutex> lock(priority_mutex_);
    if (!lifted_ && !boosted_ && worker_.backlog() + 1 >= capacity_) {
      boosted_ = true;
      ++catch_ups_;
      worker_.setIdlePriority(false);
    }
  }
  worker_.post([this, bytes = std::move(bytes)]() mutable {
    Opened o;
    const uint8_t* payload = nullptr;
    o.refusal = auth_.open(channel_, bytes.data(), bytes.size(), &payload, &o.size);
    if (!o.refusal) o.offset = static_cast<size_t>(payload - bytes.data());
    o.bytes = std::move(bytes);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      opened_.push_back(std::move(o));
    }
    std::lock_guard<std::mutex> lock(priority_mutex_);
    if (boosted_ && !lifted_ && worker_.backlog() == 0) {  // caught up: back to the idle time
      boosted_ = false;
      worker_.setIdlePriority(true);
    }
  });
}

std::vector<ScanOpener::Opened> ScanOpener::take() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<Opened> out;
  out.swap(opened_);
  return out;
}

void ScanOpener::wait(bool lift) {
  if (lift) {
    {
      std::lock_guard<std::mutex> lock(priority_mutex_);
      lifted_ = true;
    }
    worker_.drain();
  } else {
    worker_.wait();
  }
}

}  // namespace dlslot::mapper
