// The life of a track, one definition for the tracker and the backend:
//   tentative -> confirmed (min_hits detections inside the window) -> coasting (predicted through
//   misses) -> ended (more than max_misses frames in a row without a detection).
// Each track carries a confidence in [0, 1] from its detections' scores and its hit ratio; it is
// the score column of every results file, so that score-swept metrics (sAMOTA) rank tracks by it.
// The per-class numbers (score threshold, gate, hits, misses) are a ClassPolicy.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace dlslot {

// Values as track_t::STATUS_* / association_t::STATUS_*.
enum class TrackStatus : int8_t { Tentative = 0, Confirmed = 1, Coasting = 2 };
const char* trackStatusName(TrackStatus status);

// How a detector's raw score becomes a probability-like confidence in [0, 1].
enum class ScoreScale {
  Logit,        // PointRCNN and most 3-D detectors publish raw logits: sigmoid(score)
  Probability,  // already in [0, 1] (clamped)
};
ScoreScale scoreScaleFromName(const std::string& name);  // "logit" | "probability"
double detectionConfidence(double score, ScoreScale scale);

// The tracking policy of one class group (e.g. car = Car, Van, Truck).
struct ClassPolicy {
  std::string name;                // "car", "pedestrian", "cyclist"
  std::vector<std::string> types;  // KITTI types it covers
  double min_score = -1e300;       // detections scoring below this (raw score) start no track
  // Detections between this and min_score only extend confirmed tracks (a second, weaker tier, as
  // in ByteTrack): a real object the detector is less sure of in one frame keeps its track, while
  // the detector's many weak false positives never become tracks. Below it they are not tracked.
  double min_score_to_extend = -1e300;
  // Association gate (eq. 6-7, made per class and anisotropic): a detection is admissible when
  // it lies inside an ellipse around the prediction whose axes are `gate_across_m` across the
  // predicted motion and `gate_along_m` along it; a trajectory predicting with its last position
  // (fewer than g observations) has no motion direction and uses the circle `young_gate_m`.
  // Every axis grows by `gate_growth_mps` per second since the trajectory was last seen.
  double gate_across_m = 2.0;
  double gate_along_m = 2.0;
  double young_gate_m = 4.0;
  double gate_growth_mps = 1.0;
  // Eq. 3 fits a cubic; slow, noisy movers (pedestrians) are predicted better by a line: a
  // higher degree extrapolates a short, noisy history into a neighbour's place.
  int max_polynomial_degree = 3;
  int min_hits = 3;    // detections inside the window before a track is confirmed
  int max_misses = 5;  // frames in a row without a detection before a track ends
  // A confirmed track missed by the detector is still reported, at its predicted position, for
  // this many frames (<= max_misses): a detector blinks more often than an object vanishes.
  int output_coasting_frames = 0;
  // Added to the score column of a track that moved over ground (tracker/track_evidence.hpp), in
  // the detector's raw score units: motion as evidence that the track is a real object.
  double moving_evidence = 0.0;

  void validate() const;  // std::invalid_argument naming the bad field
};

// The policy covering `type`, or nullptr when no policy names it (such detections are not tracked).
const ClassPolicy* policyFor(const std::vector<ClassPolicy>& policies, const std::string& type);

class TrackLifecycle {
 public:
  // A track starts with its first detection (confidence from detectionConfidence).
  TrackLifecycle(double detection_confidence, const ClassPolicy& policy);

  // A detection joined the track; window_hits = its detections inside the window, this one included.
  void hit(double detection_confidence, int window_hits, const ClassPolicy& policy);
  // A frame passed without a detection.
  void miss();

  TrackStatus status() const;
  bool confirmed() const { return confirmed_; }
  bool ended(const ClassPolicy& policy) const { return misses_ > policy.max_misses; }
  int misses() const { return misses_; }
  int hits() const { return hits_; }
  // Mean detection confidence of the recent detections, times the fraction of the recent frames
  // that had one (and, while tentative, the fraction of the hits it needs): a consistently
  // detected track scores high, a flickering or unconfirmed one low.
  double confidence() const;

 private:
  double score_mean_;       // exponential mean of the detections' confidences
  double hit_ratio_ = 1.0;  // exponential mean of hit (1) / miss (0) over frames
  double evidence_ = 1.0;   // tentative: window hits / min_hits (a young track ranks below a confirmed one)
  int hits_ = 1, misses_ = 0;
  bool confirmed_ = false;
};

}  // namespace dlslot
