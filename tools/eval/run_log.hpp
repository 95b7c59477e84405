// Reading a recorded run (an lcm-logger file) into the evaluator's types. The only part of the
// evaluator that sees LCM.
#pragma once

#include <map>
#include <set>
#include <string>

#include "dlslot/config.hpp"
#include "dlslot/process_status_t.hpp"
#include "dlslot/timing_stats.hpp"
#include "ego_metrics.hpp"
#include "tracking_frames.hpp"
#include "trajectory.hpp"

namespace dlslot::eval {

struct RunLog {
  std::map<std::string, Trajectory> sources;  // "odometry" (ODOMETRY pose), "slot" (SLOT_STATE ego_pose)
  Trajectory truth;                           // GROUND_TRUTH poses (frames with has_pose)
  struct Labels {
    double stamp = 0;
    std::vector<Box> boxes, dontcare;  // lidar frame
  };
  std::map<int, Labels> labels;  // GROUND_TRUTH boxes by frame
  struct Tracks {
    double stamp = 0;
    Pose ego = Pose::Identity();  // the SLOT_STATE's own ego pose, used to move the tracks
    std::vector<Object> objects;  // lidar frame; velocity in the lidar axes
  };
  std::map<int, Tracks> tracks;  // SLOT_STATE tracks by frame
  std::set<int> frames;          // every frame index a pipeline message carried
  std::map<std::string, TimingStats> timing_ms;  // "<process>" (stage "total") or "<process>.<stage>"
  std::map<std::string, int64_t> frame_counts;   // accepted messages per frame channel
  std::map<std::string, int64_t> refused;        // "CHANNEL.REASON" -> events skipped (message_guard.hpp)
  std::map<std::string, process_status_t> last_status;  // by process name
  // Resident memory over the run by process: (PROCESS_STATUS utime in s, counter rss_kb).
  std::map<std::string, std::vector<std::pair<double, int64_t>>> rss_kb;
  std::optional<OdometryChecks> odometry_checks;  // from SLOT_STATE, when the log has any
};

// Reads every event; throws InputError naming the file for a missing, empty, truncated or corrupt
// log; a message that the guard refuses (message_guard.hpp) is skipped, logged and counted in
// `refused`. Tracks not observed within the
// last `track_max_unseen` frames (track_t.last_seen_frame) are not part of a frame's output.
RunLog readRunLog(const std::string& path, const Channels& channels, int track_max_unseen = 0);

}  // namespace dlslot::eval
