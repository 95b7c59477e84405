// Sliding-window trajectory association (paper III-B) with the tracking initialization of III-D.
#pragma once

#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "dlslot/track_lifecycle.hpp"
#include "dlslot/types.hpp"
#include "trajectory_predictor.hpp"

namespace dlslot::tracker {

// How a trajectory predicts its position at the new frame.
enum class Predictor {
  Polynomial,    // the paper: least-squares polynomial once a trajectory has g observations
  LastPosition,  // baseline: nearest neighbour on the last position, for every trajectory
};
Predictor predictorFromName(const std::string& name);  // "polynomial" | "last_position"

// The default per-class policies (config/dlslot.yaml has the tuned ones): car = Car, Van,
// Truck; pedestrian = Pedestrian, Person_sitting; cyclist = Cyclist.
std::vector<ClassPolicy> defaultClassPolicies();

// What a class's objects can plausibly do over a window, beyond a single detector vote; each
// decision is taken once the window spans min_span_s and sticks to the track:
// - a track moving faster than max_speed_mps (its least-squares velocity over the window) is not
//   of this class. It is re-labelled as `too_fast_type` (e.g. a "pedestrian" at cyclist speed is
//   a cyclist the detector has no class file for), or suppressed when that is empty;
// - with yields_to_other_classes, a track whose boxes sat inside the box of a track of another
//   class (another class group, or one re-labelled) at half or more of its window's observations
//   is that other object seen a second time by the detector (a pedestrian box on a cyclist that
//   is already tracked as one, or on a car): suppressed. The same rule as the duplicate
//   suppression of one frame (a detection centred inside another's footprint), held over the
//   window, so it also covers the frames where the other class's box was the less confident one.
struct ClassPlausibility {
  double max_speed_mps = std::numeric_limits<double>::infinity();
  std::string too_fast_type;
  double min_span_s = 0.5;
  bool yields_to_other_classes = false;
};

struct AssociatorConfig {
  int window_frames = 10;             // k: observations of the last k frames are kept
  int init_observations = 3;          // g: observations needed to fit and be "initialized"
  Predictor predictor = Predictor::Polynomial;
  double max_noise_gain = 3.0;        // lower the degree while the fit extrapolates noise more (predictPolynomial)
  double dynamic_displacement_m = 1.0;  // window displacement above which a trajectory is dynamic
  ScoreScale score_scale = ScoreScale::Logit;  // how detection scores become confidences
  // Two detections on one object (e.g. a Car and a Pedestrian box from two class files): the
  // less confident one is dropped when its centre lies inside the other's footprint grown by
  // this margin (bird's-eye view).
  double duplicate_margin_m = 0.0;
  // Per class: score threshold, gate (eq. 6, theta), hits to confirm, misses to end. Detections
  // of a type no policy names are not tracked (counted in FrameAssociations).
  std::vector<ClassPolicy> classes = defaultClassPolicies();
  // By class name (ClassPolicy::name); a class without an entry is always plausible.
  std::map<std::string, ClassPlausibility> plausibility;

  void validate() const;  // std::invalid_argument naming the bad field
};

// A trajectory Tr^u: its observations o^u inside the window (oldest first) and its latest box.
struct Trajectory {
  int id = -1;
  Box last_box;  // world frame, the latest detection
  int last_frame = -1;
  double last_time_s = 0.0;
  std::vector<TrajectoryPoint> window;
  double displacement = 0.0;
  bool is_dynamic = false;
  int policy = -1;  // index into AssociatorConfig::classes: the class group it is gated with
  TrackLifecycle lifecycle{0.0, ClassPolicy{}};
  // Set once the window's evidence overruled the track's class (ClassPlausibility): the type it
  // is reported as from then on; "" with `suppressed` when its rows are not reported at all.
  std::string relabelled_as;
  bool suppressed = false;
  bool classDecided() const { return suppressed || !relabelled_as.empty(); }
};

// The outcome for one detection of the frame.
struct Association {
  int detection_index = -1;   // index into the detections given to associate()
  int track_id = -1;
  bool initialized = false;   // matched a trajectory with >= g observations (predicted by its fit, III-D)
  bool new_track = false;     // the detection started a trajectory
  int num_observations = 0;   // in the window, this one included
  Box box_lidar;              // b_t
  Box box_world;              // o_t = X_t * b_t (eq. 1)
  std::optional<Eigen::Vector3d> predicted;  // the trajectory's predicted position at this frame
  bool is_dynamic = false;
  double displacement = 0.0;
  TrackStatus status = TrackStatus::Tentative;  // of the trajectory after this detection
  double confidence = 0.0;    // [0, 1], the trajectory's confidence after this detection
  // Its class's plausibility (ClassPlausibility): re-labelled (box types carry the new type) or
  // suppressed (the track is not to be reported).
  bool relabelled = false, suppressed = false;
};

// A confirmed trajectory the detector missed at this frame, reported at its prediction
// (ClassPolicy::output_coasting_frames).
struct CoastingTrack {
  int track_id = -1;
  int missed_frames = 0;  // frames since its last detection, this one included
  Box box_world;          // its last box moved to the predicted position
  Box box_lidar;          // the same in this scan's lidar frame
  double confidence = 0.0;
};

// Detections that were not associated, and why (nothing is dropped silently).
struct SkippedDetections {
  int untracked_type = 0;  // no class policy names the type
  int below_score = 0;     // under the class's min_score
  int duplicate = 0;       // inside a more confident detection of the same frame
  int total() const { return untracked_type + below_score + duplicate; }
};

// Tracks whose class the window's evidence overrules, by reason (ClassPlausibility), counted once
// a track, when it is decided.
struct ClassDecisions {
  int relabelled_too_fast = 0;
  int suppressed_too_fast = 0;
  int suppressed_on_other_class = 0;
  ClassDecisions& operator+=(const ClassDecisions& o) {
    relabelled_too_fast += o.relabelled_too_fast;
    suppressed_too_fast += o.suppressed_too_fast;
    suppressed_on_other_class += o.suppressed_on_other_class;
    return *this;
  }
};

struct FrameAssociations {
  std::vector<Association> associations;  // one per tracked detection, in detection order
  SkippedDetections skipped;              // the detections without an association
  ClassDecisions class_decisions;         // tracks re-labelled or suppressed at this frame
  std::vector<CoastingTrack> coasting;    // confirmed trajectories reported through a miss
  int num_active_tracks = 0;              // trajectories alive after this frame
  int num_ended_tracks = 0;               // trajectories that ended at this frame
};

class TrajectoryAssociator {
 public:
  explicit TrajectoryAssociator(AssociatorConfig config = {});

  // Associates the detections b_t (lidar frame of scan `frame`, taken at time_s) seen from ego
  // pose X_t = T_world_lidar. Frames must increase; gaps are allowed (trajectories age by frame
  // index). Every tracked detection (its class has a policy, its score passes, it is no
  // duplicate) comes back with a track id: matched, or a new trajectory.
  FrameAssociations associate(int frame, double time_s, const Pose& X_t, const std::vector<Box>& detections);

  const std::vector<Trajectory>& trajectories() const { return trajectories_; }
  const AssociatorConfig& config() const { return config_; }
  void reset();

 private:
  // Counts the frames missed since the last call, drops trajectories unseen for too long (their
  // class's max_misses) and observations older than the window.
  int endAndSlide(int frame);
  // Which detections are tracked: policy, score threshold, duplicate suppression.
  std::vector<int> trackedDetections(const std::vector<Box>& detections, SkippedDetections& skipped) const;
  // Eq. 6-7 per class: trajectory u's gate at this frame (see gateOf in the .cpp).
  struct Gate {
    Eigen::Vector2d center, along_unit;  // the prediction, the unit vector of the predicted motion
    double along = 1, across = 1;        // semi-axes (equal for a circle)
    // Distance of `p` in gates: < 1 inside.
    double distance(const Eigen::Vector2d& p) const;
  };
  Gate gateOf(const Trajectory& tr, const Eigen::Vector3d& predicted, bool initialized, double time_s) const;
  // The position a trajectory predicts for time_s, and whether that prediction makes it initialized.
  Eigen::Vector3d predict(const Trajectory& tr, double time_s, bool* initialized) const;
  // The rules of ClassPlausibility on the trajectories that took the frame's detections
  // (`trajectory_of_association[i]` for out.associations[i], -1 when it took none).
  void decideClasses(const std::vector<int>& trajectory_of_association, FrameAssociations& out);

  AssociatorConfig config_;
  std::vector<Trajectory> trajectories_;
  int next_id_ = 0;
  int last_frame_ = -1;
  bool started_ = false;
};

}  // namespace dlslot::tracker
