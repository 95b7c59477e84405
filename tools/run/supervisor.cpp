#include "supervisor.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <deque>
#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace dlslot::run {

namespace {

double seconds(const rusage& u) {
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

// CPU seconds (user + system) a running process has used so far, from /proc/PID/stat; -1 when
// it cannot be read.
double runningCpuSeconds(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // Fields after the command (which may hold spaces) start after its closing parenthesis;
  // utime and stime are the 14th and 15th fields of the line, the 12th and 13th after it.
  const auto close = text.rfind(')');
  if (close == std::string::npos) return -1.0;
  std::istringstream fields(text.substr(close + 2));
  std::string skip;
  for (int i = 0; i < 11; ++i) fields >> skip;
  long long utime = 0, stime = 0;
  if (!(fields >> utime >> stime)) return -1.0;
  return static_cast<double>(utime + stime) / static_cast<double>(sysconf(_SC_CLK_TCK));
}

}  // namespace

Supervisor::~Supervisor() { stopAll(2.0); }

void Supervisor::start(const std::string& name, const std::vector<std::string>& argv, const std::string& log_path) {
  const pid_t parent = getpid(), group = group_;
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("cannot start " + name + ": fork failed");
  if (pid == 0) {
    // No child outlives the launcher, however it ends (SIGKILL included): the kernel sends SIGTERM
    // (a clean stop: the logger closes its log) when the launcher dies. It may have died already.
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(128 + SIGTERM);
    const int fd = open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) {
      dup2(fd, 1);
      dup2(fd, 2);
    }
    // One process group for all children, apart from the launcher's: a Ctrl-C on the terminal
    // reaches the launcher, which stops them in order (a new group when the old one is gone).
    if (setpgid(0, group) != 0) setpgid(0, 0);
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    execv(args[0], args.data());
    std::fprintf(stderr, "cannot execute %s\n", args[0]);
    _exit(127);
  }
  if (setpgid(pid, group) != 0) setpgid(pid, pid);  // the same in the parent: no race with exec
  if (const pid_t g = getpgid(pid); g > 0) group_ = g;
  children_.push_back({name, log_path, pid});
}

std::string Supervisor::describe(int code) {
  if (code > 128) return "killed by signal " + std::to_string(code - 128);
  return "exited with code " + std::to_string(code);
}

bool Supervisor::poll(Child& c) {
  if (c.done) return true;
  int status = 0;
  rusage usage{};
  if (wait4(c.pid, &status, WNOHANG, &usage) == c.pid) {
    c.done = true;
    c.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    c.cpu_s = seconds(usage);
  }
  return c.done;
}

std::optional<Supervisor::Exit> Supervisor::reap() {
  for (Child& c : children_) {
    if (c.reported || !poll(c)) continue;
    c.reported = true;
    return Exit{c.name, c.code, describe(c.code)};
  }
  return std::nullopt;
}

bool Supervisor::running(const std::string& name) { return !poll(find(name)); }

int Supervisor::stop(const std::string& name, double grace_s, const std::function<void()>& idle) {
  Child& c = find(name);
  c.reported = true;  // stopped on purpose: the caller gets the code
  if (!running(name)) return c.code;
  kill(c.pid, SIGINT);
  using Clock = std::chrono::steady_clock;
  const auto grace = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(grace_s));
  const auto hard_deadline = Clock::now() + 10 * grace;
  auto worked = Clock::now(), checked = worked;
  double cpu = runningCpuSeconds(c.pid);
  while (running(name) && Clock::now() < std::min(worked + grace, hard_deadline)) {
    if (idle)
      idle();
    else
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    if (Clock::now() - checked > std::chrono::milliseconds(500)) {
      checked = Clock::now();
      const double now_cpu = runningCpuSeconds(c.pid);
      if (now_cpu > cpu) worked = checked;
      cpu = now_cpu;
    }
  }
  if (running(name)) {
    kill(c.pid, SIGKILL);
    int status = 0;
    rusage usage{};
    wait4(c.pid, &status, 0, &usage);
    c.done = true;
    c.code = 128 + SIGKILL;
    c.cpu_s = seconds(usage);
  }
  return c.code;
}

void Supervisor::stopAll(double grace_s) {
  for (auto it = children_.rbegin(); it != children_.rend(); ++it)
    if (!it->done) stop(it->name, grace_s);
}

std::string Supervisor::tail(const std::string& name, int n) const {
  std::ifstream in(find(name).log);
  std::deque<std::string> lines;
  for (std::string line; std::getline(in, line);) {
    lines.push_back(line);
    if (static_cast<int>(lines.size()) > n) lines.pop_front();
  }
  std::string out;
  for (const auto& l : lines) out += "    " + l + "\n";
  return out;
}

double Supervisor::cpuSeconds(const std::string& name) const { return find(name).cpu_s; }

const std::string& Supervisor::logPath(const std::string& name) const { return find(name).log; }

Supervisor::Child& Supervisor::find(const std::string& name) {
  for (Child& c : children_)
    if (c.name == name) return c;
  throw std::logic_error("no process named " + name);
}

const Supervisor::Child& Supervisor::find(const std::string& name) const {
  for (const Child& c : children_)
    if (c.name == name) return c;
  throw std::logic_error("no process named " + name);
}

std::string readText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace dlslot::run
