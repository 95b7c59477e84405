#include "dlslot/frame_accounting.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

namespace dlslot {

int64_t statusCounter(const process_status_t& s, const std::string& name) {
  const size_t n = std::min(s.counter_names.size(), s.counter_values.size());
  for (size_t i = 0; i < n; ++i)
    if (s.counter_names[i] == name) return s.counter_values[i];
  return 0;
}

FrameAccounting accountFrames(const std::map<std::string, process_status_t>& last, int64_t played,
                              const std::vector<std::string>& pipeline) {
  FrameAccounting a;
  if (const auto p = last.find("player"); p != last.end()) played = p->second.frames_handled;
  a.played = played;
  auto counter = [&](const std::string& process, const std::string& name) -> int64_t {
    const auto it = last.find(process);
    return it == last.end() ? 0 : statusCounter(it->second, name);
  };
  for (const std::string& name : pipeline) {
    ProcessFrames f;
    f.name = name;
    if (const auto it = last.find(name); it != last.end()) {
      f.reported = true;
      f.handled = it->second.frames_handled;
      f.received = statusCounter(it->second, "frames_received");
      f.skipped = statusCounter(it->second, "frames_skipped");
    }
    f.lost = std::max<int64_t>(0, played - f.handled - f.skipped);
    a.processes.push_back(f);
  }
  a.without_odometry = counter("backend", "odometry_missing");
  a.without_associations = counter("backend", "associations_missing");
  a.without_detections = std::max(counter("odometry", "unfiltered_frames"), counter("tracker", "detections_missing"));
  // Each process's own socket, plus what the launcher counted on the sockets of processes that do
  // not report (lcm-logger's).
  for (const auto& [name, s] : last) a.kernel_drops += statusCounter(s, "udp_drops") + statusCounter(s, "udp_drops_elsewhere");
  return a;
}

int64_t FrameAccounting::lost() const {
  int64_t n = 0;
  for (const ProcessFrames& p : processes) n += p.lost;
  return n;
}

bool FrameAccounting::hasLoss() const {
  return lost() > 0 || without_odometry > 0 || without_associations > 0 || without_detections > 0 ||
         kernel_drops > 0;
}

std::string FrameAccounting::verdict() const {
  std::ostringstream os;
  if (!hasLoss()) {
    os << "0 frames lost: " << played << " played, every one handled or skipped on purpose by ";
    std::string skipped;
    for (size_t i = 0; i < processes.size(); ++i) {
      os << (i ? ", " : "") << processes[i].name;
      if (processes[i].skipped > 0)
        skipped += "; " + processes[i].name + " skipped " + std::to_string(processes[i].skipped) + " on purpose";
    }
    os << skipped;
    return os.str();
  }
  os << "LOSSES: " << lost() << " frames lost of " << played << " played";
  std::string where;
  for (const ProcessFrames& p : processes)
    if (p.lost > 0) where += (where.empty() ? "" : ", ") + p.name + " " + std::to_string(p.lost);
  if (!where.empty()) os << " (" << where << ")";
  if (without_odometry) os << "; " << without_odometry << " solved without odometry";
  if (without_associations) os << "; " << without_associations << " solved without associations";
  if (without_detections) os << "; " << without_detections << " without detections";
  if (kernel_drops) os << "; " << kernel_drops << " UDP datagrams dropped by the kernel (receive buffer full)";
  return os.str();
}

std::string FrameAccounting::table() const {
  std::ostringstream os;
  char line[160];
  std::snprintf(line, sizeof line, "  %-10s %9s %9s %9s %9s\n", "process", "received", "handled", "skipped", "lost");
  os << "frames: " << played << " played\n" << line;
  for (const ProcessFrames& p : processes) {
    if (p.reported)
      std::snprintf(line, sizeof line, "  %-10s %9lld %9lld %9lld %9lld\n", p.name.c_str(),
                    static_cast<long long>(p.received), static_cast<long long>(p.handled),
                    static_cast<long long>(p.skipped), static_cast<long long>(p.lost));
    else
      std::snprintf(line, sizeof line, "  %-10s %9s %9s %9s %9lld (no PROCESS_STATUS)\n", p.name.c_str(), "-", "-",
                    "-", static_cast<long long>(p.lost));
    os << line;
  }
  os << "  solved without odometry " << without_odometry << ", without associations " << without_associations
     << ", without detections " << without_detections << "; kernel UDP drops " << kernel_drops << "\n";
  return os.str();
}

std::optional<RssSummary> summarizeRss(const std::vector<std::pair<double, int64_t>>& samples) {
  if (samples.empty()) return std::nullopt;
  const auto mbAt = [&](double fraction) {
    const double t = samples.front().first + fraction * (samples.back().first - samples.front().first);
    const auto nearest = std::min_element(samples.begin(), samples.end(), [&](const auto& x, const auto& y) {
      return std::abs(x.first - t) < std::abs(y.first - t);
    });
    return nearest->second / 1024.0;
  };
  return RssSummary{mbAt(0.0), mbAt(0.5), mbAt(0.75), mbAt(1.0)};
}

int64_t residentKb() {
  std::ifstream in("/proc/self/statm");
  int64_t size = 0, resident = 0;
  if (!(in >> size >> resident)) return 0;
  return resident * (sysconf(_SC_PAGESIZE) / 1024);
}

}  // namespace dlslot
