#include "dlslot/node.hpp"

#include <poll.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <csignal>
#include <cstdlib>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <set>
#include <sstream>
#include <stdexcept>

#include "dlslot/frame_accounting.hpp"
#include "dlslot/input_error.hpp"
#include "dlslot/large_message_filter.hpp"
#include "dlslot/receive_buffer.hpp"

namespace dlslot {

// ---------------- CommandLine ----------------

std::vector<std::string> splitList(const std::string& value) {
  std::vector<std::string> out;
  std::stringstream is(value);
  for (std::string item; std::getline(is, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

CommandLine::CommandLine(std::string program, std::string summary)
    : program_(std::move(program)), summary_(std::move(summary)) {}

void CommandLine::option(const std::string& name, std::string* value, const std::string& help) {
  opts_.push_back({name, help, [value](const std::string& v) { *value = v; }});
}

void CommandLine::option(const std::string& name, double* value, const std::string& help) {
  opts_.push_back({name, help, [name, value](const std::string& v) {
                     size_t used = 0;
                     try {
                       *value = std::stod(v, &used);
                     } catch (...) {
                     }
                     if (used != v.size() || v.empty())
                       throw std::invalid_argument(name + ": expected a number, got '" + v + "'");
                     // nan and inf parse, but no option means them (--speed nan once meant lockstep).
                     if (!std::isfinite(*value))
                       throw std::invalid_argument(name + ": expected a finite number, got '" + v + "'");
                   }});
}

void CommandLine::option(const std::string& name, int* value, const std::string& help) {
  opts_.push_back({name, help, [name, value](const std::string& v) {
                     size_t used = 0;
                     try {
                       *value = std::stoi(v, &used);
                     } catch (...) {
                     }
                     if (used != v.size() || v.empty())
                       throw std::invalid_argument(name + ": expected an integer, got '" + v + "'");
                   }});
}

void CommandLine::repeated(const std::string& name, std::vector<std::string>* values, const std::string& help) {
  opts_.push_back({name, help + " (repeatable)", [values](const std::string& v) { values->push_back(v); }});
}

void CommandLine::action(const std::string& name, std::function<void(const std::string&)> apply,
                         const std::string& help, bool takes_value) {
  Opt o{name, help, std::move(apply)};
  o.is_flag = !takes_value;
  opts_.push_back(o);
}

void CommandLine::flag(const std::string& name, bool* value, const std::string& help) {
  Opt o{name, help, [value](const std::string&) { *value = true; }};
  o.is_flag = true;
  opts_.push_back(o);
}

std::string CommandLine::usage() const {
  std::ostringstream os;
  os << "usage: " << program_ << " [options]\n" << summary_ << "\n\noptions:\n";
  for (const Opt& o : opts_) {
    std::string lhs = o.name + (o.is_flag ? "" : " VALUE");
    os << "  " << lhs << std::string(lhs.size() < 26 ? 26 - lhs.size() : 1, ' ') << o.help << "\n";
  }
  os << "  --help                    show this help\n";
  return os.str();
}

bool CommandLine::parse(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      std::cout << usage();
      return false;
    }
    std::string value;
    bool has_inline = false;
    if (auto eq = arg.find('='); arg.rfind("--", 0) == 0 && eq != std::string::npos) {
      value = arg.substr(eq + 1);
      arg = arg.substr(0, eq);
      has_inline = true;
    }
    auto it = std::find_if(opts_.begin(), opts_.end(), [&](const Opt& o) { return o.name == arg; });
    if (it == opts_.end()) throw std::invalid_argument("unknown option '" + arg + "' (see --help)");
    if (!it->is_flag && !has_inline) {
      if (i + 1 >= argc) throw std::invalid_argument(arg + ": missing value");
      value = argv[++i];
    }
    it->set(value);
  }
  return true;
}

void NodeOptions::addTo(CommandLine& cl) {
  cl.option("--config", &config, "YAML config file (default config/dlslot.yaml)");
  cl.option("--lcm-url", &lcm_url, "LCM URL (default: $LCM_DEFAULT_URL or LCM's default)");
  cl.flag("--check-config", &check_config, "load and validate the config, then exit");
  cl.action("--key", useKeyFile,
            "key file authenticating this run's messages (default: $DLSLOT_KEY_FILE; the launcher makes one)");
  cl.action("--insecure", [](const std::string&) { useNoKey(); }, "no message authentication (open LCM)", false);
}

void JoinTimeoutOption::addTo(CommandLine& cl, const std::string& what) {
  cl.option("--join-timeout", &seconds,
            "seconds to wait for " + what + "; dlslot-run lengthens it in lockstep, where no later frame comes before "
            "this one is solved");
}

double JoinTimeoutOption::resolve(double configured_s) const {
  if (std::isnan(seconds)) return configured_s;
  if (!(seconds > 0)) throw std::invalid_argument("--join-timeout: expected a time > 0 (s)");
  return seconds;
}

void useKeyFile(const std::string& path) {
  if (path.empty()) throw std::invalid_argument("--key: expected a key file");
  const std::string abs = std::filesystem::absolute(path).string();
  readKeyFile(abs);  // refused now, naming the file, rather than in every process
  setenv(kKeyFileEnv, abs.c_str(), 1);
}

void useNoKey() { unsetenv(kKeyFileEnv); }

// ---------------- ProcessStatus ----------------

namespace {

double processCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

// DLSLOT_SLOWDOWN=NAME:FRACTION[,NAME:FRACTION...]: the fraction of extra CPU time the process
// named NAME burns per frame (0 when not named or malformed).
double slowdownFor(const std::string& name) {
  const char* env = std::getenv("DLSLOT_SLOWDOWN");
  if (!env) return 0;
  for (const std::string& item : splitList(env)) {
    const size_t colon = item.find(':');
    if (colon == std::string::npos || item.substr(0, colon) != name) continue;
    char* end = nullptr;
    const double f = std::strtod(item.c_str() + colon + 1, &end);
    if (end && *end == '\0' && f > 0 && f < 100) return f;
    std::fprintf(stderr, "[%s] DLSLOT_SLOWDOWN: '%s' is not NAME:FRACTION; ignored\n", name.c_str(), item.c_str());
  }
  return 0;
}

}  // namespace

ProcessStatus::ProcessStatus(std::string name) : name_(std::move(name)) {}

void ProcessStatus::frameDone(int frame, double ms) {
  ++frames_;
  last_frame_ = frame;
  times_.add(ms);
  // Test hook of the speed guard (./dlslot bench, docs/performance.md): DLSLOT_SLOWDOWN=NAME:FRACTION
  // makes the process whose (first) status is NAME burn that fraction of its CPU time since the
  // previous frame (every thread's) in a loop, so its CPU per frame grows by the fraction.
  static const double slowdown = [this] {
    const double f = slowdownFor(name_);
    if (f > 0)
      std::fprintf(stderr, "[%s] DLSLOT_SLOWDOWN: burning %.0f %% more CPU time per frame (a test of the speed guard)\n",
                   name_.c_str(), 100 * f);
    return f;
  }();
  static double cpu_at_last_frame = processCpuSeconds();
  if (slowdown > 0) {
    const double now = processCpuSeconds();
    const double until = now + slowdown * (now - cpu_at_last_frame);
    volatile double sink = 0;
    while (processCpuSeconds() < until) sink = sink + 1;
    cpu_at_last_frame = processCpuSeconds();
  }
}

void ProcessStatus::decodeError(const std::string& channel) {
  ++decode_errors_;
  warn("could not decode a message on " + channel + " (skipped)");
}

void ProcessStatus::refused(const std::string& channel, const Refusal& why, const std::string& where) {
  static const std::set<std::string> malformed = {"fingerprint", "truncated", "bad_count", "bad_string",
                                                  "trailing_bytes", "decode", "decode_exception"};
  if (malformed.count(why.reason))
    ++decode_errors_;
  else
    ++errors_;
  const std::string key = "refused." + channel + "." + why.reason;
  if (counters_[key]++ == 0)
    warn(where + channel + ": refused a message (" + why.reason + ": " + why.detail + "); more of this kind are only counted");
  else
    last_warning_ = channel + ": refused a message (" + why.reason + ")";
}

std::map<std::string, int64_t> ProcessStatus::refusals() const {
  std::map<std::string, int64_t> out;
  const std::string prefix = "refused.";
  for (const auto& [k, v] : counters_)
    if (k.rfind(prefix, 0) == 0) out[k.substr(prefix.size())] = v;
  return out;
}

void ProcessStatus::frameGap(const std::string& channel, int expected, int got) {
  gaps_ += static_cast<int64_t>(got) - expected;
  warn(channel + ": frame gap, expected frame " + std::to_string(expected) + ", got " + std::to_string(got));
}

void ProcessStatus::timeout(const std::string& what) {
  ++timeouts_;
  warn("timeout: " + what);
}

void ProcessStatus::error(const std::string& what) {
  ++errors_;
  warn(what);
}

void ProcessStatus::warn(const std::string& what) {
  last_warning_ = what;
  std::fprintf(stderr, "[%s] %s\n", name_.c_str(), what.c_str());
}

void ProcessStatus::count(const std::string& counter, int64_t by) { counters_[counter] += by; }

int64_t ProcessStatus::counter(const std::string& counter) const {
  auto it = counters_.find(counter);
  return it == counters_.end() ? 0 : it->second;
}

process_status_t ProcessStatus::toMessage() const {
  process_status_t m;
  m.utime = std::chrono::duration_cast<std::chrono::microseconds>(
                std::chrono::system_clock::now().time_since_epoch())
                .count();
  m.name = name_;
  m.pid = getpid();
  m.frames_handled = frames_;
  m.last_frame = last_frame_;
  m.time_mean_ms = times_.mean();
  m.time_p95_ms = times_.percentile(95);
  m.time_max_ms = times_.max();
  m.decode_errors = decode_errors_;
  m.frame_gaps = gaps_;
  m.timeouts = timeouts_;
  m.errors = errors_;
  m.last_warning = last_warning_;
  for (const auto& [k, v] : counters_) {
    m.counter_names.push_back(k);
    m.counter_values.push_back(v);
  }
  m.num_counters = static_cast<int32_t>(m.counter_names.size());
  return m;
}

// ---------------- signals ----------------

namespace {
std::atomic<bool> g_signal{false};
void onSignal(int) { g_signal = true; }
}  // namespace

void installSignalHandlers() {
  struct sigaction sa {};
  sa.sa_handler = onSignal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

bool signalReceived() { return g_signal; }

// ---------------- Node ----------------

Node::Node(std::string name, const std::string& lcm_url, const Channels& channels)
    : name_(std::move(name)), lcm_(lcm_url), channels_(channels), status_(name_) {
  if (std::optional<RunKey> key = keyFromEnvironment()) {
    auth_ = MessageAuth(*key);
    std::fprintf(stderr, "[%s] messages authenticated with the run key %s (run %s)\n", name_.c_str(),
                 std::getenv(kKeyFileEnv), key->runIdHex().c_str());
  } else {
    std::fprintf(stderr, "[%s] no run key (--key FILE or $%s): messages are neither signed nor verified\n",
                 name_.c_str(), kKeyFileEnv);
  }
  status_.set("authenticated", auth_.enabled() ? 1 : 0);
  if (!lcm_.good())
    throw std::runtime_error("cannot initialise LCM with URL '" +
                             (lcm_url.empty() ? std::string("(default)") : lcm_url) + "'");
  const char* env = std::getenv("LCM_DEFAULT_URL");
  const std::string url = !lcm_url.empty() ? lcm_url : env ? env : "";
  if (const int port = lcmPort(url); port > 0) {
    // LCM's receive socket is the one that appears when LCM makes it (on first use): any other on
    // the port was inherited (dlslot-run's children hold the launcher's, a test's launcher the
    // test's), and a filter or buffer size set on it would act on the other process's socket.
    const std::vector<int> before = udpSocketsOnPort(port);
    lcm_.getFileno();
    for (const int fd : udpSocketsOnPort(port))
      if (std::find(before.begin(), before.end(), fd) == before.end()) recv_fd_ = fd;
  }
  url_buffer_bytes_ = requestedReceiveBuffer(url);
  if (recv_fd_ >= 0) {
    setReceiveBuffer(1);
    // No subscription yet, so no point cloud is wanted until one subscribes to the scan channel.
    filtering_large_ = attachLargeMessageFilter(recv_fd_);
  }
  // The player's start events, for every node (handleRunEvent).
  subscribe<run_event_t>(channels_.run_event, [this](const run_event_t& e) { handleRunEvent(e); });
}

void Node::noteSubscription(const std::string& channel) {
  if (channel == channels_.scan && filtering_large_) filtering_large_ = !detachLargeMessageFilter(recv_fd_);
}

void Node::handleRunEvent(const run_event_t& e) {
  bool started = !frames_received_.empty();
  for (const auto& [channel, order] : frame_order_) started = started || order.last() >= 0;
  if (!started) return;  // the first start of the run: nothing to forget
  status_.count("restarts");
  status_.warn("the player started again (sequence " + e.sequence + " from frame " + std::to_string(e.first_frame) +
               "): starting over");
  for (auto& [channel, order] : frame_order_) order.reset();
  frames_received_.clear();
  for (const auto& cb : restart_handlers_) cb(e);
}

void Node::publishStart(int first_frame, const std::string& sequence) {
  run_event_t e;
  e.utime = std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
                .count();
  e.event = "start";
  e.first_frame = first_frame;
  e.sequence = sequence;
  publish(channels_.run_event, e);
}

void Node::noteFrameReceived(int frame) {
  if (frames_received_.insert(frame).second) status_.count("frames_received");
}

void Node::checkSize(const std::string& channel, int64_t bytes) {
  if (bytes >= kLargeMessageBytes)
    status_.error("a message on " + channel + " is " + std::to_string(bytes) +
                  " bytes: processes that take no scans do not receive messages of " +
                  std::to_string(kLargeMessageBytes) + " bytes or more (large_message_filter.hpp)");
}

void Node::subscribeRaw(const std::string& channel, RawHandler cb) { addHandler(channel, std::move(cb), false); }

void Node::subscribeSealed(const std::string& channel, RawHandler cb) { addHandler(channel, std::move(cb), true); }

void Node::addHandler(const std::string& channel, RawHandler cb, bool sealed) {
  noteSubscription(channel);
  for (ChannelHandlers& h : handlers_)
    if (h.channel == channel) {
      if (h.sealed != sealed)
        throw std::logic_error(channel + ": a channel's handlers are either all sealed or all opened");
      h.handlers.push_back(std::move(cb));
      return;
    }
  handlers_.push_back({this, channel, {std::move(cb)}, sealed});
  lcm_.subscribeFunction<ChannelHandlers*>(
      channel, [](const lcm::ReceiveBuffer* rbuf, const std::string&, ChannelHandlers* h) { h->node->dispatch(*h, *rbuf); },
      &handlers_.back());
}

void Node::dispatch(ChannelHandlers& h, const lcm::ReceiveBuffer& rbuf) {
  if (h.sealed) {
    for (size_t i = 0; i < h.handlers.size(); ++i) h.handlers[i](rbuf);
    return;
  }
  // The envelope first: nothing unauthenticated reaches a decoder or any state.
  const uint8_t* payload = nullptr;
  size_t size = 0;
  if (const Refusal why = auth_.open(h.channel, rbuf.data, rbuf.data_size, &payload, &size)) {
    status_.refused(h.channel, why);
    return;
  }
  lcm::ReceiveBuffer inner = rbuf;
  inner.data = const_cast<uint8_t*>(payload);
  inner.data_size = static_cast<uint32_t>(size);
  for (size_t i = 0; i < h.handlers.size(); ++i) h.handlers[i](inner);
}

void Node::publishSealed(const std::string& channel, size_t payload_size) {
  auth_.seal(channel, out_buf_.data(), payload_size);
  if (lcm_.publish(channel, out_buf_.data(), static_cast<unsigned>(out_buf_.size())) != 0)
    status_.error("publish on " + channel + " failed");
}

void Node::publishEncoded(const std::string& channel, const void* data, size_t size) {
  if (channel != channels_.scan) checkSize(channel, static_cast<int64_t>(size));
  out_buf_.resize(auth_.headerBytes() + size + auth_.tagBytes());
  if (size) std::memcpy(out_buf_.data() + auth_.headerBytes(), data, size);
  publishSealed(channel, size);
}

void Node::every(double period_s, std::function<void()> cb) {
  timers_.push_back({Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(period_s)),
                     period_s, std::move(cb)});
}

void Node::after(double delay_s, std::function<void()> cb) {
  timers_.push_back({Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(delay_s)),
                     0.0, std::move(cb)});
}

void Node::setReceiveBuffer(int times_url) {
  if (recv_fd_ < 0 || url_buffer_bytes_ <= 0) return;
  const ReceiveBuffer rb = enlargeReceiveBuffer(recv_fd_, url_buffer_bytes_ * times_url);
  status_.set("recv_buffer_bytes", rb.granted);
  std::fprintf(stderr, "[%s] %s\n", name_.c_str(), rb.note.c_str());
}

void Node::publishStatus() {
  // The heartbeat carries the process's memory and the datagrams its socket lost.
  status_.set("rss_kb", residentKb());
  if (recv_fd_ >= 0) status_.set("udp_drops", std::max<int64_t>(0, udpDrops(recv_fd_)));
  publish(channels_.status, status_.toMessage());
}

void Node::handleOnce(double max_wait_s) {
  // Wait for LCM traffic or the next timer, whichever comes first.
  auto now = Clock::now();
  double wait = max_wait_s;
  for (const Timer& t : timers_) wait = std::min(wait, std::chrono::duration<double>(t.next - now).count());
  pollfd pfd{lcm_.getFileno(), POLLIN, 0};
  // Rounded up: rounded down, the last millisecond before every timer was a loop of poll(0)
  // calls (the backend's 10 ms timer kept a fifth of its CPU time in poll).
  const int timeout_ms = std::max(0, static_cast<int>(std::ceil(wait * 1000.0)));
  if (poll(&pfd, 1, timeout_ms) > 0 && (pfd.revents & POLLIN)) lcm_.handle();

  now = Clock::now();
  // Run due timers; a callback may add timers, so iterate by index over a snapshot size.
  const size_t n = timers_.size();
  std::vector<size_t> expired;
  for (size_t i = 0; i < n; ++i) {
    if (timers_[i].next > now) continue;
    auto cb = timers_[i].cb;
    if (timers_[i].period_s > 0)
      timers_[i].next = now + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timers_[i].period_s));
    else
      expired.push_back(i);
    cb();
  }
  for (auto it = expired.rbegin(); it != expired.rend(); ++it) timers_.erase(timers_.begin() + *it);
}

int Node::run() {
  installSignalHandlers();
  every(1.0, [this] { publishStatus(); });
  publishStatus();
  while (!stop_ && !signalReceived()) handleOnce(0.1);
  publishStatus();
  return 0;
}

bool Node::spinUntil(const std::function<bool()>& pred, double timeout_s) {
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout_s));
  while (!pred()) {
    const double left = std::chrono::duration<double>(deadline - Clock::now()).count();
    if (left <= 0 || signalReceived()) return pred();
    handleOnce(std::min(left, 0.05));
  }
  return true;
}

int runMain(const std::string& program, const std::function<int()>& body) {
  try {
    return body();
  } catch (const std::invalid_argument& e) {
    std::cerr << program << ": " << e.what() << "\n";
    return 2;
  } catch (const ConfigError& e) {
    std::cerr << program << ": config error: " << e.what() << "\n";
    return 2;
  } catch (const InputError& e) {
    std::cerr << program << ": bad input: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << program << ": error: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace dlslot

namespace dlslot {
int frameOfEncoded(const void* data, size_t size) {
  if (size < 20) return -1;
  const auto* b = static_cast<const uint8_t*>(data) + 16;  // hash (8) + utime (8), big-endian
  return static_cast<int32_t>((uint32_t(b[0]) << 24) | (uint32_t(b[1]) << 16) | (uint32_t(b[2]) << 8) | uint32_t(b[3]));
}
}  // namespace dlslot
