// Detection scores on PointRCNN's scale. The detector's own score (the logit of a confidence from
// the fit, object_class.cpp) says little about how often a box is right, and the tracker's
// thresholds (tracker.classes.*.min_score) were chosen for PointRCNN's logits. So each class
// group maps its raw score through a table measured offline (scripts/score-calibration.py): a
// raw score whose detections were right with precision p becomes the PointRCNN score at which
// PointRCNN's detections were right with the same p. Then one tracker policy fits both sources,
// and a detection file written by the detector means what a PointRCNN file means.
#pragma once

#include <string>
#include <vector>

#include "dlslot/config.hpp"

namespace dlslot::detector {

// A monotone piecewise-linear map raw -> calibrated through the knots (raw strictly increasing,
// calibrated non-decreasing), constant beyond the first and last knot.
struct ScoreTable {
  std::vector<double> raw, calibrated;
  double operator()(double raw_score) const;
  // Throws std::invalid_argument naming what is wrong (empty, sizes differ, not monotone).
  void validate() const;
};

// One table per class group: vehicle (Car, Van, Truck), pedestrian (Pedestrian), cyclist
// (Cyclist). Other types (Unknown: never tracked) keep their raw score.
struct ScoreCalibration {
  // The shipped tables (config/dlslot.yaml), so tests can start from DetectorConfig{}.
  ScoreTable vehicle{{0.42, 0.71, 1.29, 2.56}, {-0.26, 2.6, 4.71, 5.28}};
  ScoreTable pedestrian{{0.83, 1.32, 2.06, 5.11}, {1.99, 3.83, 4.22, 5.67}};
  ScoreTable cyclist{{2.75, 5.26}, {-0.45, 6.81}};
  double apply(const std::string& type, double raw_score) const;

  // The `score_calibration` section: {vehicle: {raw: [...], calibrated: [...]}, pedestrian: ..., cyclist: ...}.
  // Throws ConfigError naming the file and the key.
  static ScoreCalibration read(ConfigSection section);
};

}  // namespace dlslot::detector
