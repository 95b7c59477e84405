// A peer on a running pipeline's bus, for the tests that play a hostile publisher: it hears the
// frame channels as raw bytes while the run goes on, and publishes what the test hands it, paced
// so the receivers' socket buffers hold it (losses are not what those tests are about).
#pragma once

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include <chrono>
#include <functional>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "message_samples.hpp"
#include "process_harness.hpp"

namespace dlslot::test {

inline const std::vector<std::string> kFrameChannels = {"LIDAR_SCAN", "DETECTIONS",   "GROUND_TRUTH",
                                                        "ODOMETRY",   "ASSOCIATIONS", "SLOT_STATE"};

class BusPeer {
 public:
  // Called for every message heard on a frame channel (our own come back too); it may send.
  using Handler = std::function<void(BusPeer& peer, const std::string& channel, const Bytes& bytes)>;

  explicit BusPeer(Handler on_message) : on_message_(std::move(on_message)) {
    EXPECT_TRUE(lcm_.good());
    for (const std::string& ch : kFrameChannels)
      subs_.push_back(lcm_.subscribeFunction<BusPeer*>(
          ch,
          [](const lcm::ReceiveBuffer* rbuf, const std::string& channel, BusPeer* self) {
            const auto* d = static_cast<const uint8_t*>(rbuf->data);
            self->on_message_(*self, channel, Bytes(d, d + rbuf->data_size));
          },
          this));
  }
  ~BusPeer() {
    for (lcm::Subscription* s : subs_) lcm_.unsubscribe(s);
  }
  BusPeer(const BusPeer&) = delete;
  BusPeer& operator=(const BusPeer&) = delete;

  void send(const std::string& channel, const Bytes& b) {
    ASSERT_EQ(lcm_.publish(channel, b.data(), static_cast<unsigned>(b.size())), 0);
    ++sent[channel];
    std::this_thread::sleep_for(std::chrono::milliseconds(b.size() > 100000 ? 40 : 3));
  }

  // Listens (and lets the handler send) until `run` exits; returns its exit code.
  int listenUntilExit(ChildProcess& run) {
    while (run.running()) lcm_.handleTimeout(20);
    return run.wait(0);
  }

  std::map<std::string, int> sent;  // channel -> messages this peer published

 private:
  Handler on_message_;
  lcm::LCM lcm_;
  std::vector<lcm::Subscription*> subs_;
};

}  // namespace dlslot::test
