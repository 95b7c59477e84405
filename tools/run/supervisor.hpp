// Starts the pipeline's processes, watches them, and stops them cleanly: the launcher's
// LCM-free part. Each child's stdout and stderr go to its own log file, so a failure can be
// reported with the process's name and its last lines.
#pragma once

#include <sys/types.h>

#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace dlslot::run {

class Supervisor {
 public:
  ~Supervisor();  // stops whatever still runs

  // Starts argv[0] with argv; output to log_path. Throws std::runtime_error when fork fails.
  // Children share one process group (not the launcher's) and get SIGTERM when the launcher dies.
  void start(const std::string& name, const std::vector<std::string>& argv, const std::string& log_path);

  // A child that has exited and was not reported yet (running() may have noticed the exit
  // first): its name and a description ("exited with code 3", "killed by signal 9"). Children
  // stopped by stop() are not reported.
  struct Exit {
    std::string name;
    int code = 0;  // exit code, or 128 + signal
    std::string how;
  };
  std::optional<Exit> reap();
  bool running(const std::string& name);

  // SIGINT to `name`, SIGKILL once it has used no CPU for grace_s (or after ten graces whatever
  // it does); returns its exit code (128 + signal when killed). A process still working when
  // asked to stop (the renderer writing its backlog of images on a loaded machine) is finishing,
  // not hung. `idle` (if given) is called repeatedly while waiting, instead of sleeping.
  int stop(const std::string& name, double grace_s = 5.0, const std::function<void()>& idle = {});
  // Stops every running child, newest first.
  void stopAll(double grace_s = 5.0);

  // CPU seconds (user + system) a child used, known once it has exited (else -1).
  double cpuSeconds(const std::string& name) const;

  // The last n lines of a child's log.
  std::string tail(const std::string& name, int n = 15) const;
  const std::string& logPath(const std::string& name) const;

 private:
  struct Child {
    std::string name, log;
    pid_t pid = -1;
    bool done = false;      // exited (or stopped)
    bool reported = false;  // by reap(), or stopped on purpose
    int code = 0;
    double cpu_s = -1.0;    // user + system, from wait4 at exit
  };
  // Notes the exit of c if it has exited; true when it has.
  static bool poll(Child& c);
  Child& find(const std::string& name);
  const Child& find(const std::string& name) const;
  static std::string describe(int code);
  std::vector<Child> children_;
  pid_t group_ = 0;  // the children's process group (0: none yet)
};

// Reads a small text file whole ("" when missing).
std::string readText(const std::string& path);

}  // namespace dlslot::run
