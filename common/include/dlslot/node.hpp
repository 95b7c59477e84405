// What every DL-SLOT process shares: command line, config, an event loop on the LCM file
// descriptor with timers, clean exit on SIGINT/SIGTERM, PROCESS_STATUS at 1 Hz, and typed
// publish/subscribe helpers that count (never crash on) messages they cannot decode.
#pragma once

#include <lcm/lcm-cpp.hpp>

#include <chrono>
#include <functional>
#include <list>
#include <map>
#include <memory>
#include <set>
#include <limits>
#include <string>
#include <vector>

#include "dlslot/config.hpp"
#include "dlslot/message_auth.hpp"
#include "dlslot/message_guard.hpp"
#include "dlslot/process_status_t.hpp"
#include "dlslot/run_event_t.hpp"
#include "dlslot/timing_stats.hpp"

namespace dlslot {

// The items of a comma-separated option value ("0000,0002" -> {"0000", "0002"}; empty items dropped).
std::vector<std::string> splitList(const std::string& value);

// A small option parser: --name VALUE options, --flag switches, --help.
class CommandLine {
 public:
  CommandLine(std::string program, std::string summary);
  void option(const std::string& name, std::string* value, const std::string& help);
  void option(const std::string& name, double* value, const std::string& help);
  void option(const std::string& name, int* value, const std::string& help);
  void repeated(const std::string& name, std::vector<std::string>* values, const std::string& help);
  void flag(const std::string& name, bool* value, const std::string& help);
  // An option whose value is handed to `apply` as it is parsed (apply may throw invalid_argument);
  // a switch (no value) when `takes_value` is false.
  void action(const std::string& name, std::function<void(const std::string&)> apply, const std::string& help,
              bool takes_value = true);
  // Parses argv. Prints usage and returns false for --help; throws std::invalid_argument with a
  // clear message for an unknown option or a bad value.
  bool parse(int argc, char** argv);
  std::string usage() const;

 private:
  struct Opt {
    std::string name, help;
    std::function<void(const std::string&)> set;
    bool is_flag = false;
  };
  std::string program_, summary_;
  std::vector<Opt> opts_;
};

// The options every process takes: --config FILE, --lcm-url URL, --check-config, and the
// authentication of its messages (message_auth.hpp): --key FILE (sets $DLSLOT_KEY_FILE, which
// the launcher sets for its children) or --insecure (no key: today's open LCM).
struct NodeOptions {
  std::string config = "config/dlslot.yaml";
  std::string lcm_url;  // empty: $LCM_DEFAULT_URL or LCM's default
  bool check_config = false;
  void addTo(CommandLine& cl);
};
// --join-timeout SECONDS for a node that waits for a frame's inputs: it overrides the config's wait.
// dlslot-run lengthens the waits in lockstep, where no later frame comes before this one is solved,
// so an input that is merely slow (a loaded machine, a sanitizer build) is not taken for a lost one.
struct JoinTimeoutOption {
  double seconds = std::numeric_limits<double>::quiet_NaN();  // NaN: not given
  // `what`: the wait and the config key it overrides, for --help.
  void addTo(CommandLine& cl, const std::string& what);
  // The given value (> 0, else invalid_argument), or `configured_s` when none was given.
  double resolve(double configured_s) const;
};

// What --key FILE and --insecure do: point $DLSLOT_KEY_FILE at FILE (checked at once, made
// absolute), or clear it. Every Node made afterwards uses that key (or none).
void useKeyFile(const std::string& path);
void useNoKey();

// Counters and timing a process reports in PROCESS_STATUS.
class ProcessStatus {
 public:
  explicit ProcessStatus(std::string name);
  void frameDone(int frame, double ms);  // one frame handled in `ms` milliseconds
  void decodeError(const std::string& channel);
  // A message refused by the guard (message_guard.hpp): counted as "refused.CHANNEL.REASON" (and in
  // decode_errors when it was malformed, errors when its content was), logged once per reason.
  // `where` (e.g. "LOG: event 12: ") starts the logged line of an offline reader.
  void refused(const std::string& channel, const Refusal& why, const std::string& where = "");
  // The refused messages counted so far: "CHANNEL.REASON" -> count.
  std::map<std::string, int64_t> refusals() const;
  void frameGap(const std::string& channel, int expected, int got);
  void timeout(const std::string& what);
  void error(const std::string& what);
  void warn(const std::string& what);  // logged to stderr and kept as last_warning
  void count(const std::string& counter, int64_t by = 1);
  void set(const std::string& counter, int64_t value) { counters_[counter] = value; }
  int64_t counter(const std::string& counter) const;
  int64_t framesHandled() const { return frames_; }
  process_status_t toMessage() const;

 private:
  std::string name_;
  int64_t frames_ = 0;
  int last_frame_ = -1;
  TimingStats times_;
  int64_t decode_errors_ = 0, gaps_ = 0, timeouts_ = 0, errors_ = 0;
  std::string last_warning_;
  std::map<std::string, int64_t> counters_;
};

class Node {
 public:
  using Clock = std::chrono::steady_clock;

  // Throws std::runtime_error naming the URL when LCM cannot be initialised. When the URL (or
  // $LCM_DEFAULT_URL) asks for recv_buf_size, the receive socket is made at once and its buffer
  // enlarged past net.core.rmem_max where allowed (receive_buffer.hpp); the size granted is
  // logged and reported as the counter recv_buffer_bytes.
  Node(std::string name, const std::string& lcm_url, const Channels& channels = Channels());

  lcm::LCM& lcm() { return lcm_; }
  ProcessStatus& status() { return status_; }
  const std::string& name() const { return name_; }

  // Calls `cb` with the raw bytes of every message on `channel` (LCM 1.3 takes no lambdas), its
  // envelope opened: only authenticated messages reach `cb`.
  using RawHandler = std::function<void(const lcm::ReceiveBuffer&)>;
  void subscribeRaw(const std::string& channel, RawHandler cb);
  // Calls `cb` with every message on `channel` as it arrived, its envelope NOT opened: for a
  // process that opens a large message off LCM's receiving thread (the MAC of a 2 MB scan costs
  // ~0.7 ms). Nothing in the bytes may be trusted or acted on before MessageAuth::open accepts
  // them; `channel` then has only sealed handlers.
  void subscribeSealed(const std::string& channel, RawHandler cb);
  // Decodes through the guard (decodeChecked) and calls `cb`; a refused message is counted and
  // logged (ProcessStatus::refused), never thrown, and an exception from `cb` is counted too.
  template <class Msg>
  void subscribe(const std::string& channel, std::function<void(const Msg&)> cb);
  // Same, for frame-indexed messages (a `frame` field): a frame that is not new or too far ahead
  // is refused (FrameOrder), a jump in the frame index is a gap.
  template <class Msg>
  void subscribeFrames(const std::string& channel, std::function<void(const Msg&)> cb);
  // Encodes `msg` and publishes it, in an authenticated envelope when the process has a key.
  template <class Msg>
  void publish(const std::string& channel, const Msg& msg) {
    const int size = msg.getEncodedSize();
    if (channel != channels_.scan) checkSize(channel, size);
    out_buf_.resize(auth_.headerBytes() + static_cast<size_t>(size) + auth_.tagBytes());
    if (msg.encode(out_buf_.data() + auth_.headerBytes(), 0, size) != size) {
      status_.error("encoding a message for " + channel + " failed");
      return;
    }
    publishSealed(channel, static_cast<size_t>(size));
  }
  // Publishes already-encoded bytes (in an envelope when the process has a key).
  void publishEncoded(const std::string& channel, const void* data, size_t size);
  const MessageAuth& auth() const { return auth_; }

  // Calls `cb` when the player starts a run again (a "start" RUN_EVENT after this node handled
  // frames): every channel's frame order is reset first, so the new numbering is accepted. The only
  // way a node starts over: old, duplicate or far frames never reset one (message_guard.hpp).
  void onRestart(std::function<void(const run_event_t&)> cb) { restart_handlers_.push_back(std::move(cb)); }
  // Publishes the player's "start" event.
  void publishStart(int first_frame, const std::string& sequence);

  // Calls cb every period_s seconds from the loop.
  void every(double period_s, std::function<void()> cb);
  // Calls cb once, after delay_s seconds.
  void after(double delay_s, std::function<void()> cb);

  // Handles messages and timers until SIGINT/SIGTERM or stop(). Publishes PROCESS_STATUS every
  // second and once more on exit. Returns the process exit code (0).
  int run();
  // Handles messages until pred() is true or timeout_s passes; returns pred(). For tests/tools.
  bool spinUntil(const std::function<bool()>& pred, double timeout_s);
  void stop() { stop_ = true; }
  void publishStatus();
  // The receive buffer: `times_url` x the URL's recv_buf_size (the constructor asks for 1x; a
  // process that lags the pipeline by design asks for more); logged and reported as
  // recv_buffer_bytes. Nothing when the URL asks for none.
  void setReceiveBuffer(int times_url);

 private:
  void handleOnce(double max_wait_s);
  void noteFrameReceived(int frame);
  void publishSealed(const std::string& channel, size_t payload_size);
  void noteSubscription(const std::string& channel);
  // A message this large on a channel other than the scan is trimmed away by the large-message
  // filter of every process that takes no scans (large_message_filter.hpp): reported as an error.
  void checkSize(const std::string& channel, int64_t bytes);
  struct Timer {
    Clock::time_point next;
    double period_s;  // 0 = one-shot
    std::function<void()> cb;
  };
  std::string name_;
  lcm::LCM lcm_;
  Channels channels_;
  ProcessStatus status_;
  std::vector<Timer> timers_;
  std::map<std::string, FrameOrder> frame_order_;
  std::set<int> frames_received_;  // distinct frames that any frame channel carried
  int64_t url_buffer_bytes_ = 0;   // the URL's recv_buf_size (0: none asked)
  int recv_fd_ = -1;               // LCM's receive socket, for its kernel drop count
  void handleRunEvent(const run_event_t& e);
  MessageAuth auth_;
  std::vector<uint8_t> out_buf_;
  std::vector<std::function<void(const run_event_t&)>> restart_handlers_;
  // One LCM subscription per channel (so an envelope is verified once, whatever the number of
  // handlers): stable addresses, LCM keeps a pointer to each channel's entry.
  struct ChannelHandlers {
    Node* node;
    std::string channel;
    std::vector<RawHandler> handlers;
    bool sealed = false;  // handed over unopened (subscribeSealed)
  };
  void addHandler(const std::string& channel, RawHandler cb, bool sealed);
  void dispatch(ChannelHandlers& h, const lcm::ReceiveBuffer& rbuf);
  std::list<ChannelHandlers> handlers_;
  bool filtering_large_ = false;  // the large-message filter is on recv_fd_ (no scan subscription)
  bool stop_ = false;
};

// Installs SIGINT/SIGTERM handlers that make every Node::run() return.
void installSignalHandlers();
bool signalReceived();

// Runs `body` and turns any exception into a message on stderr and exit code 1 (2 for a bad
// command line / config), so every main() reports bad input the same way.
int runMain(const std::string& program, const std::function<int()>& body);

// ---- template implementations ----
template <class Msg>
void Node::subscribe(const std::string& channel, std::function<void(const Msg&)> cb) {
  subscribeRaw(channel, [this, cb, channel](const lcm::ReceiveBuffer& rbuf) {
    Msg msg;
    if (const Refusal why = decodeChecked(rbuf.data, rbuf.data_size, &msg)) {
      status_.refused(channel, why);
      return;
    }
    try {
      cb(msg);
    } catch (const std::exception& e) {
      status_.refused(channel, {"handler_exception", e.what()});
    }
  });
}

template <class Msg>
void Node::subscribeFrames(const std::string& channel, std::function<void(const Msg&)> cb) {
  subscribe<Msg>(channel, [this, cb, channel](const Msg& msg) {
    FrameOrder& order = frame_order_[channel];
    const int last = order.last();
    if (const Refusal why = order.accept(msg.frame)) {
      status_.refused(channel, why);
      return;
    }
    // Frames are within [0, kMaxFrame] here, so neither `last + 1` nor the gap overflows.
    if (last >= 0 && msg.frame > last + 1) status_.frameGap(channel, last + 1, msg.frame);
    noteFrameReceived(msg.frame);
    cb(msg);
  });
}

}  // namespace dlslot

namespace dlslot {
// Every frame-indexed message type starts with `int64_t utime; int32_t frame;`, so the frame of
// an encoded message of any of these types is at a fixed offset after LCM's 8-byte type hash.
// Returns -1 when the buffer is too short. (Used by the player's lockstep to follow any channel.)
int frameOfEncoded(const void* data, size_t size);
}  // namespace dlslot
