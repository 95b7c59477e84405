// Detection recall and precision per class: labels and detections of a class group matched one to
// one by bird's-eye centre distance (closest pairs first, at most max_distance_m apart), counted
// within max_range_m of the sensor. A class group holds the label types it scores and the detected
// types that count for it (KITTI's devkit lets Car match Van; a geometric detector cannot tell a
// Car from a Van or a Truck either, so the vehicle group takes all three).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "dlslot/types.hpp"

namespace dlslot::detector {

struct EvalClass {
  std::string name;
  std::vector<std::string> types;
  bool holds(const std::string& type) const;
};
// Car {Car, Van, Truck}, Pedestrian {Pedestrian, Person_sitting}, Cyclist {Cyclist}.
std::vector<EvalClass> defaultEvalClasses();

struct MatchCounts {
  int labels = 0, detections = 0, matched = 0;
  int ignored = 0;  // unmatched detections in an ignore region (KITTI DontCare), not counted
  double recall() const { return labels ? static_cast<double>(matched) / labels : 0.0; }
  double precision() const { return detections ? static_cast<double>(matched) / detections : 0.0; }
  void add(const MatchCounts& o);
};

struct EvalOptions {
  double max_distance_m = 2.0;  // bird's-eye centre distance for a match
  double max_range_m = 40.0;    // labels and detections farther from the sensor are not counted
};

// Matches one frame's labels and detections (both lidar frame) of class `cls`. `ignore`, when
// given, is asked about each unmatched detection: true leaves it out of the count.
MatchCounts matchFrame(const std::vector<Box>& labels, const std::vector<Box>& detections, const EvalClass& cls,
                       const EvalOptions& opt, const std::function<bool(const Box&)>& ignore = {});

}  // namespace dlslot::detector
