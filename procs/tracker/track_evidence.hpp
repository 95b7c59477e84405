// The score column of the results files: one number per track, ranking tracks by the evidence
// that they are real objects, on the detector's own scale (a raw logit for PointRCNN).
//
// Score-swept metrics (sAMOTA, AMOTA; AB3DMOT's evaluate.py and dlslot-eval alike) give every track
// the mean of its rows' scores and drop whole tracks below a threshold, so what matters is how the
// tracks rank. A track's evidence is the mean detection score over its life (first to last
// detection), in which every frame it was not detected counts as a detection at the class's floor
// (the weakest score a detection may have and still be tracked: a real object the detector missed
// reads as no better than that), shrunk towards that floor by `min_hits` pseudo-frames (a track of
// one or two detections has not yet shown it is more than the detector's noise: the lifecycle's
// own confirmation count is the measure of how much evidence is "enough").
//
// A class may count motion over ground as evidence too (ClassPolicy::moving_evidence, on the same
// logit scale): the clutter a pedestrian detector takes for people (poles, trunks, sign posts,
// parked bicycles) stands still, a person often walks; a track that moved more than the paper's
// static/dynamic displacement (III-D, dynamic_displacement_m) between its first and its last
// detection, at a walking pace at least (0.5 m/s on average, the slowest gait), gains that much.
// The pace keeps out the slow drift of GPS/INS ego poses under a long track of a parked object
// (train half, 0007: a pole's track 1.1 m over 7.7 s, 0.14 m/s). It needs ego poses: tracked in
// the sensor frame (every pose the identity), a parked object moves with the ego, and no track
// gains anything.
//
// The value is written on every row of the track and rounded to a binary grid (multiples of
// 2^-20), so that a mean of n equal rows is that value exactly in floating point: the script
// averages its rows' scores anew at every pass of its sweep, and any other value drifts by
// rounding from pass to pass until the track at a threshold falls below it.
#pragma once

#include <Eigen/Core>
#include <map>
#include <set>
#include <vector>

#include "dlslot/kitti.hpp"
#include "dlslot/track_lifecycle.hpp"

namespace dlslot::tracker {

// What a track showed over its life.
struct TrackEvidence {
  double score_sum = 0.0;  // raw detection scores of its detections
  int hits = 0;            // detections
  int first_frame = -1, last_frame = -1;
  double first_time_s = 0, last_time_s = 0;
  Eigen::Vector2d first_position = Eigen::Vector2d::Zero(), last_position = Eigen::Vector2d::Zero();  // world, xy
  // A detection at `frame` (taken at time_s); `world` is the box centre in the world frame.
  void add(int frame, double score, const Eigen::Vector3d& world = Eigen::Vector3d::Zero(), double time_s = 0);
  int missed() const { return hits > 0 ? last_frame - first_frame + 1 - hits : 0; }
  double displacement() const { return (last_position - first_position).norm(); }
  double duration() const { return last_time_s - first_time_s; }
};

// Whether, and from what displacement and pace, motion over ground counts (see above).
struct MotionEvidence {
  bool ego_poses_known = false;
  double moved_m = 1.0;         // the associator's dynamic_displacement_m
  double min_speed_mps = 0.5;   // the slowest walking pace
  bool moved(const TrackEvidence& e) const {
    return ego_poses_known && e.displacement() > moved_m && e.displacement() >= min_speed_mps * e.duration();
  }
};

// The floor a missed frame counts as: the class's min_score_to_extend when it has one, else 0
// (even odds on the logit scale, the probability 0.5).
double evidenceFloor(const ClassPolicy& policy);

// The track's score (see above), before rounding.
double trackScore(const TrackEvidence& e, const ClassPolicy& policy, const MotionEvidence& motion = {});

// `v` on the binary grid of 2^-20 (a mean of equal values on it is exact for up to 2^27 rows
// while |v| < 64), moved up by grid steps until no other track of `taken` has it.
double distinctGridScore(double v, std::set<double>& taken);

// Sets the score of every row to its track's evidence. `evidence` by track id; rows of a track id
// it does not hold keep their score.
void writeTrackScores(std::vector<kitti::LabelRow>& rows, const std::map<int, TrackEvidence>& evidence,
                      const std::map<int, const ClassPolicy*>& policy_of, const MotionEvidence& motion = {});

}  // namespace dlslot::tracker
