// A progress line for long work: "label k/N  rate Hz  ETA m:ss". Redrawn in place on a
// terminal; on a pipe or log file, one line every few seconds so logs stay readable.
#pragma once

#include <chrono>
#include <string>

namespace dlslot {

class ProgressLine {
 public:
  ProgressLine(std::string label, int total);
  // `done` items finished; `extra` is appended (e.g. per-process health).
  void update(int done, const std::string& extra = "");
  void finish(const std::string& extra = "");  // final line with the mean rate, then a newline

 private:
  std::string format(int done, const std::string& extra) const;
  std::string label_;
  int total_;
  int done_ = 0;
  bool tty_;
  std::chrono::steady_clock::time_point start_, last_print_;
};

}  // namespace dlslot
