// Joins the DETECTIONS and the ODOMETRY of one scan by frame index, with a timeout so a missing
// input never stalls the pipeline. Time is passed in (seconds on any monotonic clock).
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <vector>

#include "dlslot/types.hpp"

namespace dlslot::tracker {

// The well-formed detections of one DETECTIONS message (lidar frame).
struct DetectionFrame {
  int64_t utime = 0;
  std::vector<Box> boxes;
  std::vector<int> message_index;  // index of each box in the message
  int num_rejected = 0;            // malformed boxes left out
};

struct JoinedFrame {
  int frame = 0;
  int64_t utime = 0;
  std::optional<DetectionFrame> detections;  // empty: DETECTIONS never came
  bool has_odometry = false;
  bool timed_out = false;  // released incomplete (timeout, or a later scan completed first)
};

class FrameJoiner {
 public:
  explicit FrameJoiner(double timeout_s) : timeout_s_(timeout_s) {}

  // Return false for a message of a scan already released (late or repeated): the caller counts it.
  bool addDetections(int frame, DetectionFrame detections, double now_s);
  bool addOdometry(int frame, int64_t utime, double now_s);

  // Scans ready to process, oldest first: complete ones, incomplete ones older than the timeout,
  // and incomplete ones a later complete scan overtook (inputs come in order, so theirs is lost).
  std::vector<JoinedFrame> release(double now_s);
  // Scans are released once; a scan at or before this one is stale.
  int lastReleased() const { return last_released_; }
  // Forget everything (a restarted player starts again at frame 0).
  void reset();

 private:
  struct Pending {
    JoinedFrame joined;
    double first_seen_s = 0;
  };
  Pending& pending(int frame, int64_t utime, double now_s);

  double timeout_s_;
  std::map<int, Pending> pending_;
  int last_released_ = -1;
};

}  // namespace dlslot::tracker
