// Opens the LIDAR_SCAN envelopes (message_auth.hpp) off LCM's receiving thread. The MAC over a
// ~2 MB scan costs ~0.7 ms (auth_bench), the largest part of what the mapper did at normal
// priority on every frame; on an IdleWorker at SCHED_IDLE it uses the cores' idle time instead of
// the pipeline's. Scans come out in the order they arrived, each opened or refused, and the
// receiving thread joins them (take()), so the checks after the envelope (layout, frame order)
// and their counting stay on that one thread.
// When `capacity` scans wait (the machine left no idle time), the opener runs at normal priority
// until it has caught up: a scan is never lost for want of idle time, it only costs what it cost
// before.
#pragma once

#include <atomic>
#include <string>
#include <cstdint>
#include <mutex>
#include <optional>
#include <vector>

#include "dlslot/message_auth.hpp"
#include "mapper/idle_worker.hpp"

namespace dlslot::mapper {

class ScanOpener {
 public:
  struct Opened {
    std::vector<uint8_t> bytes;   // the message as it arrived
    size_t offset = 0, size = 0;  // its payload (the LCM-encoded scan) when the envelope was accepted
    Refusal refusal;              // else why not
  };

  // key: the run's (none: open mode, envelopes are opened without verification); threaded = false
  // opens each scan in post().
  ScanOpener(const std::optional<RunKey>& key, std::string channel, bool threaded, size_t capacity);

  void post(std::vector<uint8_t> bytes);
  // The scans opened since the last call, in arrival order.
  std::vector<Opened> take();
  // Waits until every scan posted so far is opened; `lift`: at normal priority from now on (the end).
  void wait(bool lift);
  double cpuMs() const { return worker_.cpuMs(); }
  size_t maxBacklog() const { return worker_.maxBacklog(); }
  // Times the opener fell `capacity` behind and caught up at normal priority.
  int catchUps() const { return catch_ups_; }
  std::string priorityError() const { return worker_.priorityError(); }

 private:
  MessageAuth auth_;  // used on the opener's thread only (its replay record is the scan channel's)
  std::string channel_;
  size_t capacity_;
  std::mutex mutex_;
  std::vector<Opened> opened_;
  std::mutex priority_mutex_;  // the two below change together with the thread's priority
  bool boosted_ = false, lifted_ = false;
  std::atomic<int> catch_ups_{0};
  IdleWorker worker_;  // last: its thread stops before the members it uses go
};

}  // namespace dlslot::mapper
