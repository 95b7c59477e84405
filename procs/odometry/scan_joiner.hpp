// Joins LIDAR_SCAN and DETECTIONS of one scan by frame index. A scan whose detections do not
// come within the timeout is released without them (the odometry then runs unfiltered and
// says so), so a missing detector never stalls the pipeline. Time is passed in (seconds).
#pragma once

#include <map>
#include <optional>
#include <vector>

#include "dlslot/types.hpp"

namespace dlslot::odometry {

struct JoinedScan {
  Frame frame;                  // scan + detections (lidar frame)
  bool has_detections = false;  // false: timed out or overtaken, run unfiltered
};

class ScanJoiner {
 public:
  // need_detections false (A-LOAM mode): scans are released as soon as they arrive.
  ScanJoiner(double timeout_s, bool need_detections) : timeout_s_(timeout_s), need_detections_(need_detections) {}

  // Return false for a message of a scan already released (late or repeated).
  bool addScan(int frame, int64_t utime, PointCloud scan, double now_s);
  bool addDetections(int frame, std::vector<Box> boxes, double now_s);

  // Scans ready to process, oldest first: complete ones, ones waiting longer than the timeout,
  // and ones a later complete scan overtook (messages come in order, so theirs is lost).
  // Detections whose scan never came are dropped once a later scan is released.
  std::vector<JoinedScan> release(double now_s);
  int lastReleased() const { return last_released_; }
  void reset();

 private:
  struct Pending {
    std::optional<Frame> scan;
    std::optional<std::vector<Box>> boxes;
    double first_seen_s = 0;
  };
  Pending& pending(int frame, double now_s);

  double timeout_s_;
  bool need_detections_;
  std::map<int, Pending> pending_;
  int last_released_ = -1;
};

}  // namespace dlslot::odometry
