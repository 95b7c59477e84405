// Where every played frame went: per process, the frames it received, handled (turned into its
// output), skipped on purpose and lost, and the frames the backend solved without odometry or
// the tracker's associations. Computed from each process's last PROCESS_STATUS, the same way by
// the launcher (live, for its last line and exit code) and by the evaluator (from the log, for
// metrics.json and report.md), so a run that lost frames can never look complete.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "dlslot/process_status_t.hpp"

namespace dlslot {

struct ProcessFrames {
  std::string name;
  bool reported = false;  // a PROCESS_STATUS of this process was seen
  int64_t received = 0;   // distinct frames with any input (counter frames_received)
  int64_t handled = 0;    // frames_handled
  int64_t skipped = 0;    // left out on purpose (the renderer's images while its writer was behind)
  int64_t lost = 0;       // played - handled - skipped (never negative)
};

struct FrameAccounting {
  int64_t played = 0;                 // frames the player published
  std::vector<ProcessFrames> processes;  // odometry, tracker, backend, renderer (those that ran)
  int64_t without_odometry = 0;       // backend frames solved without their ODOMETRY
  int64_t without_associations = 0;  // backend frames solved without their ASSOCIATIONS
  int64_t without_detections = 0;     // frames whose DETECTIONS missed the odometry or the tracker
  int64_t kernel_drops = 0;           // UDP datagrams the kernel dropped on the processes' sockets
                                      // (counter udp_drops: receive buffer full)

  int64_t lost() const;  // sum over processes
  // True when any frame was lost, solved without an input, or a datagram dropped.
  bool hasLoss() const;
  // One line: "0 frames lost" or what was lost, where.
  std::string verdict() const;
  // A plain-text table, one row per process.
  std::string table() const;
};

// `last` holds the last PROCESS_STATUS by process name; `played` the frames the player published
// (its frames_handled when it reported, else the caller's count). `pipeline` names the processes
// expected to handle every frame, in order.
FrameAccounting accountFrames(const std::map<std::string, process_status_t>& last, int64_t played,
                              const std::vector<std::string>& pipeline);

// A counter of a PROCESS_STATUS (0 when absent).
int64_t statusCounter(const process_status_t& s, const std::string& name);

// Resident memory of a process over a run, from its PROCESS_STATUS samples (counter rss_kb).
// The sample at three quarters of the run beside the end shows whether memory is flat in a run's
// last quarter (a soak whose map stops growing half-way).
struct RssSummary {
  double start_mb = 0, middle_mb = 0, three_quarters_mb = 0, end_mb = 0;
};
// `samples`: (time in seconds, rss in kB), in time order. The middle (three-quarters) sample is the
// one nearest the half (three quarters) of the way from the first to the last time. Empty input
// gives nullopt.
std::optional<RssSummary> summarizeRss(const std::vector<std::pair<double, int64_t>>& samples);

// This process's resident set in kB (/proc/self/statm); 0 when unknown.
int64_t residentKb();

}  // namespace dlslot
