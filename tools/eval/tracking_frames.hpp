// The per-scan input of the tracking metrics. Like KITTI's own tracking evaluation, everything is
// compared frame by frame in the lidar frame of each scan: the system's world-frame tracks are
// moved into the scan's frame with the system's own ego pose, so no ego ground truth is needed.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "dlslot/types.hpp"

namespace dlslot::eval {

struct Object {
  Box box;                                  // lidar frame of the scan; id = track / label id
  std::optional<Eigen::Vector2d> velocity;  // m/s in the scan's lidar axes (bird's-eye view)
  bool dynamic = false;                     // labels: moving (see velocity.hpp)
  std::optional<Eigen::Matrix2d> velocity_covariance = std::nullopt;  // (m/s)^2, when the track gave one
};

struct TrackingFrame {
  int frame = 0;
  double stamp = 0;                 // seconds
  std::vector<Object> truth;        // labelled objects
  std::vector<Box> ignore;          // DontCare regions (and labels of classes not evaluated)
  std::vector<Object> tracks;       // the system's output
  std::optional<Pose> truth_pose;   // ground-truth T_world_lidar, when known
  std::optional<Pose> ego_pose;     // the system's own T_world_lidar, when known
};

// When a label and a track count as the same object. Classes must be compatible as in the KITTI
// devkit (kitti::classesCompatible). CentreDistance: bird's-eye centre distance <= max_distance_m;
// Iou3d: oriented-box volume IoU >= min_iou.
struct MatchCriterion {
  enum class Kind { CentreDistance, Iou3d } kind = Kind::CentreDistance;
  double max_distance_m = 2.0;
  double min_iou = 0.25;

  bool geometricMatch(const Box& truth, const Box& track) const;  // the gate alone, classes ignored
  bool matches(const Box& truth, const Box& track) const;
  // Assignment cost of a matching pair: the distance, or 1 - IoU.
  double cost(const Box& truth, const Box& track) const;
  // HOTA's localisation similarity in [0, 1] (0 for incompatible classes): the IoU, or for the
  // distance line max(0, 1 - d / max_distance_m), which is 1 at the same centre and 0 at the gate.
  double similarity(const Box& truth, const Box& track) const;
  std::string describe() const;  // e.g. "centre distance <= 2 m"
};

// Evaluates only `classes` (empty: all), as the devkit does: labels of a neighbouring class
// (compatible with an evaluated one, e.g. Van for Car) become ignore regions, labels of other
// classes and tracks of classes not evaluated are dropped.
void restrictClasses(std::vector<TrackingFrame>& frames, const std::vector<std::string>& classes);

// Removes, frame by frame, the tracks that match no label (optimal assignment under `criterion`)
// but lie in an ignore region (centre inside its footprint, or within the gate of its centre):
// such a track is neither a false nor a true positive.
void dropIgnoredTracks(std::vector<TrackingFrame>& frames, const MatchCriterion& criterion);

}  // namespace dlslot::eval
