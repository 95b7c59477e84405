// The detector over a whole KITTI-layout sequence from files, without LCM: recall and precision
// per class against the sequence's labels (detection_eval.hpp), the time per scan, and optionally
// the detections written as a KITTI tracking-format detection file (which `dlslot-player
// --detections` and `dlslot-tracker --kitti` read back).
#pragma once

#include <string>
#include <vector>

#include "detector/detection_eval.hpp"
#include "detector/detector_config.hpp"
#include "dlslot/timing_stats.hpp"

namespace dlslot::detector {

struct OfflineOptions {
  std::string root, sequence;
  int frames = -1;             // the first this many frames (-1: all)
  // Real KITTI labels cover only what camera 2 sees: count only detections inside its image, and
  // leave out unmatched ones inside a DontCare region, as KITTI's devkit does.
  bool camera_view = false;
  EvalOptions eval;
  std::string write_detections;  // a file to write (tracking format + score), "" for none
};

struct OfflineResult {
  std::vector<EvalClass> classes;
  std::vector<MatchCounts> counts;  // per class
  TimingStats detect_ms;            // detectObjects per scan
  int frames = 0, boxes = 0, unknown_boxes = 0;
  bool has_labels = false;
};

// Throws InputError / std::invalid_argument naming what is missing.
OfflineResult runOffline(const OfflineOptions& opt, const DetectorConfig& cfg);

// The result as a table: one line per class (labels, detections, matched, recall, precision) and
// the time per scan.
std::string formatResult(const OfflineResult& r, const OfflineOptions& opt);

}  // namespace dlslot::detector
