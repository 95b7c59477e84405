// CLEAR MOT (Bernardin & Stiefelhagen 2008) in bird's-eye view, frame by frame in each scan's
// lidar frame: correspondences of the previous frame are kept while they stay within the gate,
// the rest is matched by minimum total cost (Hungarian); an identity switch is a label matched to
// another track than the one it was last matched to.
#pragma once

#include <optional>
#include <vector>

#include "tracking_frames.hpp"
#include "velocity_breakdown.hpp"

namespace dlslot::eval {

struct ClearMot {
  int num_truth = 0;  // labelled objects over all frames (ignore regions excluded)
  int tp = 0, fp = 0, fn = 0, idsw = 0;
  std::optional<double> mota;    // 1 - (FN + FP + IDSW) / num_truth; null without labels
  std::optional<double> motp_m;  // mean bird's-eye centre distance of the matched pairs
  // Velocity error of matched labels that are dynamic and have a velocity on both sides.
  int velocity_pairs = 0;
  std::optional<double> velocity_rmse_mps;
  // Heading error of matched moving cars: labels of type Car that are dynamic and whose own speed
  // is at least kMovingSpeedMps (a car's heading is its direction of travel; a parked or crawling
  // car's box orientation is not what a planner reads). The yaw difference is wrapped to
  // [-180, 180) deg, so a box turned round counts as 180 deg, not 0.
  static constexpr double kMovingSpeedMps = 1.0;
  int heading_pairs = 0;
  std::optional<double> heading_rmse_deg;
  // Of those, the boxes more than 90 deg off (turned round), and the RMSE of the rest.
  int heading_reversed = 0;
  std::optional<double> heading_rmse_unreversed_deg;
  // Every matched pair with a velocity on both sides, static labels included (for the breakdown).
  std::vector<VelocityPair> velocities;
};

// `frames` in scan order, ignored tracks already removed (dropIgnoredTracks).
ClearMot evaluateClearMot(const std::vector<TrackingFrame>& frames, const MatchCriterion& criterion);

}  // namespace dlslot::eval
