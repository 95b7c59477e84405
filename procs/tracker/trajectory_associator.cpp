#include "trajectory_associator.hpp"

#include <algorithm>
#include <stdexcept>

#include "dlslot/kitti.hpp"
#include "dlslot/hungarian.hpp"

namespace dlslot::tracker {

Predictor predictorFromName(const std::string& name) {
  if (name == "polynomial") return Predictor::Polynomial;
  if (name == "last_position") return Predictor::LastPosition;
  throw std::invalid_argument("predictor: expected 'polynomial' or 'last_position', got '" + name + "'");
}

void AssociatorConfig::validate() const {
  auto fail = [](const std::string& what) { throw std::invalid_argument(what); };
  if (window_frames < 2) fail("window_frames: expected >= 2, got " + std::to_string(window_frames));
  if (init_observations < 1 || init_observations > window_frames)
    fail("init_observations: expected 1..window_frames, got " + std::to_string(init_observations));
  if (!(gate_sq_m2 > 0)) fail("gate_sq_m2: expected > 0, got " + std::to_string(gate_sq_m2));
  // A trajectory must keep at least one observation in the window while it is alive.
  if (max_missed_frames < 0 || max_missed_frames >= window_frames)
    fail("max_missed_frames: expected 0..window_frames-1, got " + std::to_string(max_missed_frames));
  if (max_polynomial_degree < 1 || max_polynomial_degree > 3)
    fail("max_polynomial_degree: expected 1..3, got " + std::to_string(max_polynomial_degree));
  if (!(max_noise_gain >= 1)) fail("max_noise_gain: expected >= 1, got " + std::to_string(max_noise_gain));
  if (!(dynamic_displacement_m >= 0))
    fail("dynamic_displacement_m: expected >= 0, got " + std::to_string(dynamic_displacement_m));
}

TrajectoryAssociator::TrajectoryAssociator(AssociatorConfig config) : config_(config) { config_.validate(); }

void TrajectoryAssociator::reset() {
  trajectories_.clear();
  next_id_ = 0;
  last_frame_ = -1;
  started_ = false;
}

int TrajectoryAssociator::endAndSlide(int frame) {
  const int before = static_cast<int>(trajectories_.size());
  // Unseen in frames last_frame+1 .. frame-1: more than max_missed_frames of them ends it.
  trajectories_.erase(std::remove_if(trajectories_.begin(), trajectories_.end(),
                                     [&](const Trajectory& tr) {
                                       return frame - 1 - tr.last_frame > config_.max_missed_frames;
                                     }),
                      trajectories_.end());
  // Tr_{t-1} = {o_{t-k}, ..., o_{t-1}}.
  const int oldest = frame - config_.window_frames;
  for (Trajectory& tr : trajectories_) {
    auto keep = std::find_if(tr.window.begin(), tr.window.end(),
                             [&](const TrajectoryPoint& p) { return p.frame >= oldest; });
    tr.window.erase(tr.window.begin(), keep);
  }
  return before - static_cast<int>(trajectories_.size());
}

Eigen::Vector3d TrajectoryAssociator::predict(const Trajectory& tr, double time_s, bool* initialized) const {
  // III-D: with g observations the trajectory is approximated by eq. 3 and its match is
  // initialized; with fewer, its last position is used and the match is not initialized.
  *initialized = static_cast<int>(tr.window.size()) >= config_.init_observations;
  if (*initialized && config_.predictor == Predictor::Polynomial)
    return predictPolynomial(tr.window, time_s, config_.max_polynomial_degree, config_.max_noise_gain).position;
  return tr.window.back().position;
}

FrameAssociations TrajectoryAssociator::associate(int frame, double time_s, const Pose& X_t,
                                                  const std::vector<Box>& detections) {
  if (started_ && frame <= last_frame_)
    throw std::invalid_argument("associate: frame " + std::to_string(frame) + " after frame " +
                                std::to_string(last_frame_) + " (frames must increase)");
  started_ = true;
  last_frame_ = frame;

  FrameAssociations out;
  out.num_ended_tracks = endAndSlide(frame);

  const int U = static_cast<int>(trajectories_.size()), V = static_cast<int>(detections.size());
  std::vector<Eigen::Vector3d> predicted(U);
  std::vector<char> initialized(U);
  for (int u = 0; u < U; ++u) {
    bool init = false;
    predicted[u] = predict(trajectories_[u], time_s, &init);
    initialized[u] = init;
  }

  out.associations.resize(V);
  for (int v = 0; v < V; ++v) {
    Association& a = out.associations[v];
    a.detection_index = v;
    a.box_lidar = detections[v];
    a.box_world = detections[v].transformed(X_t);  // eq. 1: o_t = X_t * b_t
  }

  // Eq. 6-7: a pair is admissible (score 1) when its squared bird's-eye distance is below theta
  // and the classes are compatible; the assignment maximises the number of admissible matches.
  // The binary score leaves ties, broken by a cost: initialized trajectories, whose prediction is
  // a fit, before young ones predicting with a last position that may be a false positive (a
  // matching cascade in one solve), then nearer pairs.
  Eigen::MatrixXd cost(U, V);
  Admissible admissible(U, V);
  for (int u = 0; u < U; ++u) {
    for (int v = 0; v < V; ++v) {
      const double d2 = (predicted[u].head<2>() - out.associations[v].box_world.center.head<2>()).squaredNorm();
      admissible(u, v) =
          d2 < config_.gate_sq_m2 && kitti::classesCompatible(trajectories_[u].last_box.type, detections[v].type);
      cost(u, v) = d2 / config_.gate_sq_m2 + (initialized[u] ? 0.0 : 1.0);
    }
  }
  const std::vector<int> assignment = solveGatedAssignment(cost, admissible);
  std::vector<int> trajectory_of(V, -1);
  for (int u = 0; u < U; ++u)
    if (assignment[u] >= 0) trajectory_of[assignment[u]] = u;

  for (int v = 0; v < V; ++v) {
    Association& a = out.associations[v];
    const TrajectoryPoint point{frame, time_s, a.box_world.center};
    int u = trajectory_of[v];
    if (u >= 0) {
      a.initialized = initialized[u];
      a.predicted = predicted[u];
    } else {
      // An unmatched detection starts a trajectory (III-B).
      Trajectory tr;
      tr.id = next_id_++;
      trajectories_.push_back(std::move(tr));
      u = static_cast<int>(trajectories_.size()) - 1;
      a.new_track = true;
    }
    Trajectory& tr = trajectories_[u];
    tr.window.push_back(point);
    // The window of k frames now ends at t: o_{t-k+1} .. o_t.
    if (tr.window.front().frame <= frame - config_.window_frames) tr.window.erase(tr.window.begin());
    tr.last_box = a.box_world;
    tr.last_frame = frame;
    // Preliminary static/dynamic guess from the motion over the window (III-D).
    tr.displacement = windowDisplacement(tr.window);
    tr.is_dynamic = tr.displacement > config_.dynamic_displacement_m;

    a.track_id = tr.id;
    a.num_observations = static_cast<int>(tr.window.size());
    a.displacement = tr.displacement;
    a.is_dynamic = tr.is_dynamic;
  }
  out.num_active_tracks = static_cast<int>(trajectories_.size());
  return out;
}

}  // namespace dlslot::tracker
