// Helpers for process-level tests: start real executables, stop them, read LCM logs back.
// Such tests live in *_process_test.cpp files, which CTest runs inside scripts/netns-run.
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "dlslot/lcm_log.hpp"
#include "dlslot/message_guard.hpp"
#include "dlslot/node.hpp"
#include "text_file.hpp"

namespace dlslot::test {

inline std::string sourceDir() { return DLSLOT_SOURCE_DIR; }
inline std::string binDir() { return DLSLOT_BIN_DIR; }
inline std::string bin(const std::string& name) { return binDir() + "/" + name; }
// The pipeline's config. Under the sanitizers every process runs several times slower (ASan at
// -O1, beside other tests: the odometry took over 2 s a scan), so the player's lockstep wait, and
// with it the tracker's and the backend's (dlslot-run gives them 0.4 of it), is made ten times
// longer: a slow input must not be taken for a lost one, or runs stop being deterministic.
inline std::string config() {
  const std::string shipped = sourceDir() + "/config/dlslot.yaml";
#ifdef __SANITIZE_ADDRESS__
  static const std::string slow = [&] {
    std::string yaml = readText(shipped);
    const std::string key = "lockstep_timeout_s: 5.0";
    const size_t at = yaml.find(key);
    if (at == std::string::npos) return shipped;  // changed default: the test then says what timed out
    yaml.replace(at, key.size(), "lockstep_timeout_s: 50.0");
    // Tests run in parallel: each writes its own copy, then renames it into place atomically.
    const std::string path = binDir() + "/dlslot-sanitize.yaml", tmp = path + "." + std::to_string(getpid());
    std::ofstream(tmp) << yaml;
    std::filesystem::rename(tmp, path);
    return path;
  }();
  return slow;
#else
  return shipped;
#endif
}
// A copy of the shipped config (config()) in dir/NAME.yaml with the first `from` replaced by `to`.
// The test fails when `from` is not there: the config changed under it. Replacing "key: " by
// "key: VALUE #" sets a value whatever the shipped one is (the old value becomes a comment).
inline std::string configWith(const std::string& dir, const std::string& name, const std::string& from,
                              const std::string& to) {
  std::string text = readText(config());
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "the shipped config has no \"" << from << "\"";
  if (at != std::string::npos) text.replace(at, from.size(), to);
  const std::string file = dir + "/" + name + ".yaml";
  std::ofstream(file) << text;
  return file;
}

inline std::string realDataRoot() { return sourceDir() + "/../shared/data/kitti-tracking-0000-head"; }

// A fresh scratch directory under the build tree, named after the running test.
inline std::string scratchDir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string dir = binDir() + "/../test-scratch/" + info->test_suite_name() + "." + info->name();
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

// Fails the test unless it runs in the private namespace netns-run made.
inline bool insidePrivateNetwork() { return std::getenv("DLSLOT_NETNS_INSIDE") != nullptr; }

// A child process; its stdout+stderr go to `log_path`. Stopped with SIGINT on destruction.
class ChildProcess {
 public:
  ChildProcess(std::vector<std::string> argv, std::string log_path) : log_(std::move(log_path)) {
    pid_ = fork();
    if (pid_ == 0) {
      // A test that dies (a failed assertion, a sanitizer abort) takes its children with it.
      prctl(PR_SET_PDEATHSIG, SIGKILL);
      int fd = open(log_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      dup2(fd, 1);
      dup2(fd, 2);
      std::vector<char*> args;
      for (auto& a : argv) args.push_back(a.data());
      args.push_back(nullptr);
      execv(args[0], args.data());
      _exit(127);
    }
  }
  ~ChildProcess() {
    if (running()) {
      stop();
    }
  }
  bool running() {
    if (exited_) return false;
    int status = 0;
    if (waitpid(pid_, &status, WNOHANG) == pid_) {
      exited_ = true;
      status_ = status;
      return false;
    }
    return true;
  }
  // Waits up to timeout_s for exit; returns the exit code (-1 on timeout, 128+sig when killed).
  int wait(double timeout_s) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while (running()) {
      if (std::chrono::steady_clock::now() > end) return -1;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return WIFEXITED(status_) ? WEXITSTATUS(status_) : 128 + WTERMSIG(status_);
  }
  // SIGINT, then SIGKILL after 5 s; returns the exit code.
  int stop() {
    if (!running()) return wait(0);
    kill(pid_, SIGINT);
    int code = wait(5.0);
    if (code == -1) {
      kill(pid_, SIGKILL);
      code = wait(5.0);
    }
    return code;
  }
  pid_t pid() const { return pid_; }
  std::string output() const {
    std::ifstream in(log_);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  }

 private:
  pid_t pid_ = -1;
  std::string log_;
  bool exited_ = false;
  int status_ = 0;
};

// Typed subscriptions for tests, in place of lcm-cpp's LCM::subscribe(channel, &Class::method,
// object): those hand LCM's dispatch a C++ object it calls back through (UBSan: "member access
// within address ... which does not point to an object of type 'LCMMHSubscription'") and stay
// registered until the LCM is destroyed, after the handler object may have gone. Here messages
// are decoded through the guard (refused ones skipped), and every subscription is removed when
// this object goes: declare it after the LCM and the handler object.
class Subscriptions {
 public:
  explicit Subscriptions(lcm::LCM& lcm) : lcm_(lcm) {}
  Subscriptions(const Subscriptions&) = delete;
  Subscriptions& operator=(const Subscriptions&) = delete;
  ~Subscriptions() {
    for (lcm::Subscription* s : subs_) lcm_.unsubscribe(s);
  }
  template <class Msg, class Handler>
  void subscribe(const std::string& channel,
                 void (Handler::*method)(const lcm::ReceiveBuffer*, const std::string&, const Msg*), Handler* h) {
    raw_.push_back(std::make_unique<Raw>([method, h](const lcm::ReceiveBuffer* rbuf, const std::string& ch) {
      Msg m;
      if (!decodeChecked(rbuf->data, rbuf->data_size, &m)) (h->*method)(rbuf, ch, &m);
    }));
    subs_.push_back(lcm_.subscribeFunction<Raw*>(channel, &Subscriptions::dispatch, raw_.back().get()));
  }

 private:
  using Raw = std::function<void(const lcm::ReceiveBuffer*, const std::string&)>;
  static void dispatch(const lcm::ReceiveBuffer* rbuf, const std::string& channel, Raw* raw) { (*raw)(rbuf, channel); }
  lcm::LCM& lcm_;
  std::vector<std::unique_ptr<Raw>> raw_;
  std::vector<lcm::Subscription*> subs_;
};

// Handles LCM messages until pred() holds or timeout_s passes; returns pred().
inline bool handleUntil(lcm::LCM& lcm, const std::function<bool()>& pred, double timeout_s) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (!pred()) {
    if (std::chrono::steady_clock::now() > end) return false;
    lcm.handleTimeout(20);
  }
  return true;
}

// All events of an LCM log, grouped by channel, in log order, their authentication envelopes
// opened (verified with run.key beside the log when there is one; lcm_log.hpp); events that do
// not verify are left out.
inline std::map<std::string, std::vector<std::vector<uint8_t>>> readLog(const std::string& path) {
  std::map<std::string, std::vector<std::vector<uint8_t>>> out;
  lcm::LogFile log(path, "r");
  if (!log.good()) return out;
  LogEnvelopes envelopes(path);
  ProcessStatus refused("test");
  while (const lcm::LogEvent* raw = log.readNextEvent()) {
    const lcm::LogEvent* ev = envelopes.open(*raw, refused, path + ": ");
    if (!ev) continue;
    const auto* d = static_cast<const uint8_t*>(ev->data);
    out[ev->channel].emplace_back(d, d + ev->datalen);
  }
  return out;
}

// The messages that pass the guard (message_guard.hpp); refused ones are left out.
template <class Msg>
std::vector<Msg> decodeAll(const std::vector<std::vector<uint8_t>>& raw) {
  std::vector<Msg> out;
  for (const auto& r : raw) {
    Msg m;
    if (!decodeChecked(r.data(), r.size(), &m)) out.push_back(m);
  }
  return out;
}

// /proc/PID/stat's command, state and parent pid; nothing when the process is gone.
struct ProcStat {
  std::string comm;
  char state = 0;
  pid_t ppid = 0;
};
inline std::optional<ProcStat> procStat(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string text;
  if (!std::getline(in, text)) return std::nullopt;
  const auto open = text.find('('), close = text.rfind(')');
  if (open == std::string::npos || close == std::string::npos) return std::nullopt;
  ProcStat s;
  s.comm = text.substr(open + 1, close - open - 1);
  std::istringstream rest(text.substr(close + 2));
  rest >> s.state >> s.ppid;
  return s;
}

// The pids whose parent is `parent`.
inline std::set<pid_t> childrenOf(pid_t parent) {
  std::set<pid_t> out;
  for (const auto& e : std::filesystem::directory_iterator("/proc")) {
    const std::string name = e.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    const auto s = procStat(std::stoi(name));
    if (s && s->ppid == parent) out.insert(std::stoi(name));
  }
  return out;
}

}  // namespace dlslot::test
