// The associator on a whole sequence from files, without LCM: detections and ego poses in,
// tracks in the KITTI tracking result format out, so the associations alone can be measured
// with dlslot-eval --tracks.
#pragma once

#include <string>
#include <vector>

#include "dlslot/kitti.hpp"
#include "dlslot/timing_stats.hpp"
#include "trajectory_associator.hpp"

namespace dlslot::tracker {

struct OfflineResult {
  std::vector<kitti::LabelRow> tracks;  // one row per associated detection, rectified camera frame
  TimingStats association_ms;           // per frame
  int detections = 0, initialized = 0, trajectories = 0;
};

// Runs the associator over every frame of `reader`, with ego pose X_t = ego_poses[t].
// initialized_only: output only detections whose trajectory was initialized (what the backend
// integrates, III-D); otherwise every association.
OfflineResult associateSequence(const kitti::SequenceReader& reader, const std::vector<Pose>& ego_poses,
                                const AssociatorConfig& config, bool initialized_only);

}  // namespace dlslot::tracker
