#include "dlslot/progress.hpp"

#include <unistd.h>

#include <cstdio>

namespace dlslot {

ProgressLine::ProgressLine(std::string label, int total)
    : label_(std::move(label)), total_(total), tty_(isatty(fileno(stderr))),
      start_(std::chrono::steady_clock::now()), last_print_(start_) {}

std::string ProgressLine::format(int done, const std::string& extra) const {
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const double rate = elapsed > 0 ? done / elapsed : 0.0;
  char buf[256];
  if (total_ > 0) {
    const int eta = rate > 0 ? static_cast<int>((total_ - done) / rate) : 0;
    std::snprintf(buf, sizeof buf, "%s %d/%d  %.1f Hz  ETA %d:%02d", label_.c_str(), done, total_, rate,
                  eta / 60, eta % 60);
  } else {
    std::snprintf(buf, sizeof buf, "%s %d  %.1f Hz", label_.c_str(), done, rate);
  }
  return extra.empty() ? std::string(buf) : std::string(buf) + "  " + extra;
}

void ProgressLine::update(int done, const std::string& extra) {
  done_ = done;
  const auto now = std::chrono::steady_clock::now();
  const double since = std::chrono::duration<double>(now - last_print_).count();
  if (tty_ && since >= 0.1) {
    std::fprintf(stderr, "\r\033[K%s", format(done, extra).c_str());
    last_print_ = now;
  } else if (!tty_ && since >= 5.0) {
    std::fprintf(stderr, "%s\n", format(done, extra).c_str());
    last_print_ = now;
  }
}

void ProgressLine::finish(const std::string& extra) {
  std::fprintf(stderr, "%s%s\n", tty_ ? "\r\033[K" : "", format(done_, extra).c_str());
}

}  // namespace dlslot
