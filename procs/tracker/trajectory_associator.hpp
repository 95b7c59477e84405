// Sliding-window trajectory association (paper III-B) with the tracking initialization of III-D.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "dlslot/types.hpp"
#include "trajectory_predictor.hpp"

namespace dlslot::tracker {

// How a trajectory predicts its position at the new frame.
enum class Predictor {
  Polynomial,    // the paper: least-squares polynomial once a trajectory has g observations
  LastPosition,  // baseline: nearest neighbour on the last position, for every trajectory
};
Predictor predictorFromName(const std::string& name);  // "polynomial" | "last_position"

struct AssociatorConfig {
  int window_frames = 10;             // k: observations of the last k frames are kept
  int init_observations = 3;          // g: observations needed to fit and be "initialized"
  // theta of eq. 6, on the squared bird's-eye distance (eq. 7). A young trajectory predicts with
  // its last position, so theta must exceed what a car moves in a frame (3 m at 30 m/s and 10 Hz).
  double gate_sq_m2 = 16.0;
  int max_missed_frames = 9;          // a trajectory unseen for more frames than this ends (< k)
  Predictor predictor = Predictor::Polynomial;
  int max_polynomial_degree = 3;      // eq. 3 is a cubic
  double max_noise_gain = 3.0;        // lower the degree while the fit extrapolates noise more (predictPolynomial)
  double dynamic_displacement_m = 1.0;  // window displacement above which a trajectory is dynamic

  void validate() const;  // std::invalid_argument naming the bad field
};

// A trajectory Tr^u: its observations o^u inside the window (oldest first) and its latest box.
struct Trajectory {
  int id = -1;
  Box last_box;  // world frame; type is the class the trajectory is gated with
  int last_frame = -1;
  std::vector<TrajectoryPoint> window;
  double displacement = 0.0;
  bool is_dynamic = false;
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
  int8_t status = 1;          // association_t::STATUS_* of the trajectory after this detection
  double confidence = 1.0;    // [0, 1], the trajectory's confidence after this detection
};

struct FrameAssociations {
  std::vector<Association> associations;  // one per detection, in detection order
  int num_active_tracks = 0;              // trajectories alive after this frame
  int num_ended_tracks = 0;               // trajectories that ended at this frame
};

class TrajectoryAssociator {
 public:
  explicit TrajectoryAssociator(AssociatorConfig config = {});

  // Associates the detections b_t (lidar frame of scan `frame`, taken at time_s) seen from ego
  // pose X_t = T_world_lidar. Frames must increase; gaps are allowed (trajectories age by frame
  // index). Every detection comes back with a track id: matched, or a new trajectory.
  FrameAssociations associate(int frame, double time_s, const Pose& X_t, const std::vector<Box>& detections);

  const std::vector<Trajectory>& trajectories() const { return trajectories_; }
  const AssociatorConfig& config() const { return config_; }
  void reset();

 private:
  // Drops trajectories unseen for too long and observations older than the window.
  int endAndSlide(int frame);
  // The position a trajectory predicts for time_s, and whether that prediction makes it initialized.
  Eigen::Vector3d predict(const Trajectory& tr, double time_s, bool* initialized) const;

  AssociatorConfig config_;
  std::vector<Trajectory> trajectories_;
  int next_id_ = 0;
  int last_frame_ = -1;
  bool started_ = false;
};

}  // namespace dlslot::tracker
