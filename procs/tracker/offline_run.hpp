// The associator on a whole sequence from files, without LCM: detections and ego poses in,
// tracks in the KITTI tracking result format out, so the associations alone can be measured
// with dlslot-eval --tracks (or AB3DMOT's evaluation). Scans are not needed.
#pragma once

#include <string>
#include <vector>

#include "dlslot/kitti.hpp"
#include "dlslot/timing_stats.hpp"
#include "tracker_config.hpp"
#include "trajectory_associator.hpp"

namespace dlslot::tracker {

struct OfflineResult {
  std::vector<kitti::LabelRow> tracks;  // result rows, rectified camera frame, score = track confidence
  TimingStats association_ms;           // per frame
  int detections = 0, associated = 0, confirmed = 0, trajectories = 0;
  SkippedDetections skipped;            // detections not tracked (type, score, duplicate)
  ClassDecisions class_decisions;       // tracks re-labelled or suppressed by their class's plausibility
  int suppressed_rows = 0;              // rows of suppressed tracks, not written (those before the decision too)
  int coasting = 0;                     // rows of confirmed tracks predicted through a detector miss
  int outside_image = 0;                // rows not written: the box is not in the camera image
};

// Runs the associator over every frame of `reader`, with ego pose X_t = ego_poses[t]. Writes a
// row for every association whose track is confirmed (TrackOutput::Confirmed) or for every
// association (All); the score column is the track's confidence.
// all_around: also write the rows outside the camera image (2-D box -1, alpha -10), for labels
// that cover the whole scan (the simulator's); such a file is not for the KITTI devkit.
OfflineResult associateSequence(const kitti::SequenceReader& reader, const std::vector<Pose>& ego_poses,
                                const AssociatorConfig& config, TrackOutput output, bool all_around = false);

// The ego poses to track a sequence with: `poses` (a KITTI 3x4 lidar-pose file, or a directory
// holding SSSS.txt), else the sequence's own ground truth, else identity (tracking in the sensor
// frame). `source` says which, for the terminal.
std::vector<Pose> egoPosesFor(const kitti::SequenceReader& reader, const std::string& sequence, const std::string& poses,
                              std::string* source);

}  // namespace dlslot::tracker
