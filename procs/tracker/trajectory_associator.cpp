#include "trajectory_associator.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "dlslot/hungarian.hpp"

namespace dlslot::tracker {

Predictor predictorFromName(const std::string& name) {
  if (name == "polynomial") return Predictor::Polynomial;
  if (name == "last_position") return Predictor::LastPosition;
  throw std::invalid_argument("predictor: expected 'polynomial' or 'last_position', got '" + name + "'");
}

std::vector<ClassPolicy> defaultClassPolicies() {
  ClassPolicy car;
  car.name = "car";
  car.types = {"Car", "Van", "Truck"};
  ClassPolicy pedestrian;
  pedestrian.name = "pedestrian";
  pedestrian.types = {"Pedestrian", "Person_sitting"};
  pedestrian.gate_across_m = pedestrian.gate_along_m = 1.0;
  pedestrian.young_gate_m = 1.5;
  pedestrian.max_polynomial_degree = 1;
  ClassPolicy cyclist;
  cyclist.name = "cyclist";
  cyclist.types = {"Cyclist"};
  return {car, pedestrian, cyclist};
}

void AssociatorConfig::validate() const {
  auto fail = [](const std::string& what) { throw std::invalid_argument(what); };
  if (window_frames < 2) fail("window_frames: expected >= 2, got " + std::to_string(window_frames));
  if (init_observations < 1 || init_observations > window_frames)
    fail("init_observations: expected 1..window_frames, got " + std::to_string(init_observations));
  if (!(max_noise_gain >= 1)) fail("max_noise_gain: expected >= 1, got " + std::to_string(max_noise_gain));
  if (!(dynamic_displacement_m >= 0))
    fail("dynamic_displacement_m: expected >= 0, got " + std::to_string(dynamic_displacement_m));
  if (!(duplicate_margin_m >= 0) || !std::isfinite(duplicate_margin_m))
    fail("duplicate_margin_m: expected >= 0, got " + std::to_string(duplicate_margin_m));
  for (const ClassPolicy& p : classes) {
    p.validate();
    // A trajectory must keep at least one observation in the window while it is alive, and
    // confirming needs that many observations in it.
    if (p.max_misses >= window_frames)
      fail("classes." + p.name + ".max_misses: expected 0..window_frames-1, got " + std::to_string(p.max_misses));
    if (p.min_hits > window_frames)
      fail("classes." + p.name + ".min_hits: expected 1..window_frames, got " + std::to_string(p.min_hits));
    for (const std::string& type : p.types)
      if (policyFor(classes, type) != &p)
        fail("classes." + p.name + ".types: '" + type + "' is already in class " + policyFor(classes, type)->name);
  }
}

namespace {

// Whether `p` (bird's-eye view) lies inside box `o`'s footprint grown by `margin` on every side.
bool insideFootprint(const Eigen::Vector2d& p, const Box& o, double margin) {
  const Eigen::Vector2d local = Eigen::Rotation2Dd(-o.yaw) * (p - o.center.head<2>());
  return std::abs(local.x()) <= 0.5 * o.size.x() + margin && std::abs(local.y()) <= 0.5 * o.size.y() + margin;
}

}  // namespace

TrajectoryAssociator::TrajectoryAssociator(AssociatorConfig config) : config_(std::move(config)) { config_.validate(); }

void TrajectoryAssociator::reset() {
  trajectories_.clear();
  next_id_ = 0;
  last_frame_ = -1;
  started_ = false;
}

int TrajectoryAssociator::endAndSlide(int frame) {
  // Every trajectory missed frames last_frame+1 .. frame-1; the lifecycle counts each once.
  for (Trajectory& tr : trajectories_)
    while (tr.lifecycle.misses() < frame - 1 - tr.last_frame) tr.lifecycle.miss();
  const int before = static_cast<int>(trajectories_.size());
  trajectories_.erase(std::remove_if(trajectories_.begin(), trajectories_.end(),
                                     [&](const Trajectory& tr) {
                                       return tr.lifecycle.ended(config_.classes[tr.policy]);
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
    return predictPolynomial(tr.window, time_s, config_.classes[tr.policy].max_polynomial_degree, config_.max_noise_gain).position;
  return tr.window.back().position;
}

std::vector<int> TrajectoryAssociator::trackedDetections(const std::vector<Box>& detections,
                                                         SkippedDetections& skipped) const {
  std::vector<int> candidates;
  std::vector<const ClassPolicy*> group(detections.size());
  for (int v = 0; v < static_cast<int>(detections.size()); ++v) {
    const ClassPolicy* policy = group[v] = policyFor(config_.classes, detections[v].type);
    if (!policy) {
      ++skipped.untracked_type;
    } else if (detections[v].score < policy->min_score_to_extend) {
      ++skipped.below_score;
    } else {
      candidates.push_back(v);
    }
  }
  // Duplicate suppression, most confident first: a detection whose centre falls inside a kept,
  // more confident box of another class group is the same object seen by two class files (a
  // detector's own duplicates within a class are its non-maximum suppression's business, and
  // two real cars can stand closer than a box length).
  std::stable_sort(candidates.begin(), candidates.end(),
                   [&](int a, int b) { return detections[a].score > detections[b].score; });
  std::vector<int> kept;
  for (int v : candidates) {
    const Box& d = detections[v];
    const bool duplicate = std::any_of(kept.begin(), kept.end(), [&](int k) {
      return group[k] != group[v] && insideFootprint(d.center.head<2>(), detections[k], config_.duplicate_margin_m);
    });
    if (duplicate)
      ++skipped.duplicate;
    else
      kept.push_back(v);
  }
  std::sort(kept.begin(), kept.end());
  return kept;
}

TrajectoryAssociator::Gate TrajectoryAssociator::gateOf(const Trajectory& tr, const Eigen::Vector3d& predicted,
                                                       bool initialized, double time_s) const {
  const ClassPolicy& policy = config_.classes[tr.policy];
  // The gates grow with the time the trajectory has gone unseen: its prediction spans that long.
  const double growth = policy.gate_growth_mps * std::max(0.0, time_s - tr.last_time_s);
  Gate g;
  g.center = predicted.head<2>();
  g.along_unit = Eigen::Vector2d::UnitX();
  if (!initialized || config_.predictor == Predictor::LastPosition) {
    g.along = g.across = policy.young_gate_m + growth;
    return g;
  }
  // The gate in the predicted motion's frame: along the motion the prediction is less certain
  // (speed changes) than across it (lane, pavement), so neighbours walking or driving side by
  // side are kept apart while an object that speeds up is still followed.
  const Eigen::Vector2d motion = predicted.head<2>() - tr.window.back().position.head<2>();
  g.along = policy.gate_along_m + growth;
  g.across = policy.gate_across_m + growth;
  if (motion.norm() < 1e-3) {
    g.along = g.across = std::min(g.along, g.across);  // no direction: the tighter circle
  } else {
    g.along_unit = motion.normalized();
  }
  return g;
}

double TrajectoryAssociator::Gate::distance(const Eigen::Vector2d& p) const {
  const Eigen::Vector2d d = p - center;
  const double outer = std::max(along, across);
  if (d.squaredNorm() >= outer * outer) return std::numeric_limits<double>::infinity();  // most pairs: far apart
  const double a = d.dot(along_unit), c = along_unit.x() * d.y() - along_unit.y() * d.x();
  return std::hypot(a / along, c / across);
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
  const std::vector<int> tracked = trackedDetections(detections, out.skipped);

  const int U = static_cast<int>(trajectories_.size()), V = static_cast<int>(tracked.size());
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
    a.detection_index = tracked[v];
    a.box_lidar = detections[tracked[v]];
    a.box_world = a.box_lidar.transformed(X_t);  // eq. 1: o_t = X_t * b_t
  }

  // Eq. 6-7: a pair is admissible (score 1) when the detection lies inside the trajectory's
  // class gate and belongs to the same class group. The paper's binary score makes the
  // assignment maximise the number of admissible matches; in a crowd, where gates overlap and
  // some people go undetected, that chains wrong matches (A takes B's detection so B can take
  // C's). So each admissible pair gains 1 - (its distance in gates)^2, plus a bonus for an
  // initialized trajectory, whose prediction is a fit, over a young one predicting with a last
  // position that may be a false positive (a matching cascade in one solve); the assignment
  // maximises the summed gain and leaves a pair unmatched when it gains more elsewhere.
  constexpr double kInitializedBonus = 0.5;
  std::vector<const ClassPolicy*> policy_of(V);  // looked up once per detection, not per pair
  for (int v = 0; v < V; ++v) policy_of[v] = policyFor(config_.classes, out.associations[v].box_world.type);
  Eigen::MatrixXd cost(U, V);
  Admissible admissible(U, V);
  for (int u = 0; u < U; ++u) {
    const Trajectory& tr = trajectories_[u];
    const Gate gate = gateOf(tr, predicted[u], initialized[u], time_s);
    for (int v = 0; v < V; ++v) {
      const Box& o = out.associations[v].box_world;
      const double g = gate.distance(o.center.head<2>());
      const ClassPolicy& policy = config_.classes[tr.policy];
      // A weak detection (under min_score) may only extend a confirmed track.
      const bool weak = o.score < policy.min_score;
      admissible(u, v) = g < 1.0 && policy_of[v] == &policy &&
                         (!weak || tr.lifecycle.confirmed());
      cost(u, v) = admissible(u, v) ? -(1.0 - g * g + (initialized[u] ? kInitializedBonus : 0.0)) : 0.0;
    }
  }
  const std::vector<int> assignment = solveGatedAssignment(cost, admissible, Objective::LeastCost);
  std::vector<int> trajectory_of(V, -1);
  for (int u = 0; u < U; ++u)
    if (assignment[u] >= 0) trajectory_of[assignment[u]] = u;

  std::vector<char> keep(V, 1);
  std::vector<int> trajectory_index(V, -1);  // the trajectory each kept association extended or started
  for (int v = 0; v < V; ++v) {
    Association& a = out.associations[v];
    if (trajectory_of[v] < 0 && a.box_lidar.score < policy_of[v]->min_score) {
      keep[v] = 0;  // a weak detection that extends no confirmed track starts none either
      ++out.skipped.below_score;
      continue;
    }
    const TrajectoryPoint point{frame, time_s, a.box_world.center};
    const int policy = static_cast<int>(policy_of[v] - config_.classes.data());
    const double detection_confidence = detectionConfidence(a.box_lidar.score, config_.score_scale);
    int u = trajectory_of[v];
    if (u >= 0) {
      a.initialized = initialized[u];
      a.predicted = predicted[u];
    } else {
      // An unmatched detection starts a trajectory (III-B), tentative until confirmed.
      Trajectory tr;
      tr.id = next_id_++;
      tr.policy = policy;
      tr.lifecycle = TrackLifecycle(detection_confidence, config_.classes[policy]);
      trajectories_.push_back(std::move(tr));
      u = static_cast<int>(trajectories_.size()) - 1;
      a.new_track = true;
    }
    Trajectory& tr = trajectories_[u];
    tr.window.push_back(point);
    // The window of k frames now ends at t: o_{t-k+1} .. o_t.
    if (tr.window.front().frame <= frame - config_.window_frames) tr.window.erase(tr.window.begin());
    if (!a.new_track) tr.lifecycle.hit(detection_confidence, static_cast<int>(tr.window.size()), config_.classes[policy]);
    tr.last_frame = frame;
    tr.last_time_s = time_s;
    // Preliminary static/dynamic guess from the motion over the window (III-D).
    tr.displacement = windowDisplacement(tr.window);
    tr.is_dynamic = tr.displacement > config_.dynamic_displacement_m;
    trajectory_index[v] = u;

    tr.last_box = a.box_world;
    a.track_id = tr.id;
    a.num_observations = static_cast<int>(tr.window.size());
    a.displacement = tr.displacement;
    a.is_dynamic = tr.is_dynamic;
    a.status = tr.lifecycle.status();
    a.confidence = tr.lifecycle.confidence();
  }
  decideClasses(trajectory_index, out);
  std::vector<Association> kept;
  for (int v = 0; v < V; ++v)
    if (keep[v]) kept.push_back(std::move(out.associations[v]));
  out.associations = std::move(kept);

  // Confirmed trajectories the detector missed this frame, reported at their prediction for a
  // few frames; the confidence already counts the frames missed before this one, and this miss.
  const Pose lidar_world = X_t.inverse();
  for (int u = 0; u < U; ++u) {
    const Trajectory& tr = trajectories_[u];
    const int missed = frame - tr.last_frame;
    if (assignment[u] >= 0 || !tr.lifecycle.confirmed() || tr.suppressed ||
        missed > config_.classes[tr.policy].output_coasting_frames)
      continue;
    CoastingTrack c;
    c.track_id = tr.id;
    c.missed_frames = missed;
    c.box_world = tr.last_box;
    c.box_world.center.head<2>() = predicted[u].head<2>();
    c.box_world.id = tr.id;
    c.box_lidar = c.box_world.transformed(lidar_world);
    TrackLifecycle after = tr.lifecycle;
    after.miss();
    c.confidence = after.confidence();
    c.box_world.score = c.box_lidar.score = c.confidence;
    out.coasting.push_back(c);
  }
  out.num_active_tracks = static_cast<int>(trajectories_.size());
  return out;
}

void TrajectoryAssociator::decideClasses(const std::vector<int>& trajectory_of_association, FrameAssociations& out) {
  const std::vector<int>& tr_of = trajectory_of_association;
  const int V = static_cast<int>(out.associations.size());
  auto ruleOf = [&](const Trajectory& tr) -> const ClassPlausibility* {
    if (tr.classDecided()) return nullptr;  // decided once, for the rest of its life
    const auto rule = config_.plausibility.find(config_.classes[tr.policy].name);
    return rule == config_.plausibility.end() ? nullptr : &rule->second;
  };
  // First where each box of a yielding class sits, against the classes as they stood before this
  // frame's decisions (so the order of the detections does not matter): inside the box of a
  // track of another class group, or of one re-labelled (a cyclist tracked from pedestrian boxes).
  for (int v = 0; v < V; ++v) {
    if (tr_of[v] < 0) continue;
    Trajectory& tr = trajectories_[tr_of[v]];
    const ClassPlausibility* rule = ruleOf(tr);
    if (!rule || !rule->yields_to_other_classes) continue;
    const Eigen::Vector2d centre = out.associations[v].box_world.center.head<2>();
    bool on_other = false;
    for (int w = 0; w < V && !on_other; ++w) {
      if (w == v || tr_of[w] < 0) continue;
      const Trajectory& other = trajectories_[tr_of[w]];
      if (other.policy == tr.policy && other.relabelled_as == tr.relabelled_as) continue;
      on_other = insideFootprint(centre, out.associations[w].box_world, 0.0);
    }
    tr.window.back().on_other_class = on_other;
  }
  // Then the decisions, over the window.
  for (int v = 0; v < V; ++v) {
    if (tr_of[v] < 0) continue;
    Trajectory& tr = trajectories_[tr_of[v]];
    if (const ClassPlausibility* rule = ruleOf(tr)) {
      const double span = tr.window.back().time_s - tr.window.front().time_s;
      const auto on_other = std::count_if(tr.window.begin(), tr.window.end(),
                                          [](const TrajectoryPoint& p) { return p.on_other_class; });
      if (span < rule->min_span_s) {
        // not yet enough of a window to judge
      } else if (rule->yields_to_other_classes && 2 * on_other >= static_cast<long>(tr.window.size())) {
        // Another track's object seen a second time; first, so that a second "pedestrian" on a
        // cyclist does not become a second cyclist by its speed.
        tr.suppressed = true;
        ++out.class_decisions.suppressed_on_other_class;
      } else if (tr.displacement / span > rule->max_speed_mps) {
        // Faster than its class can move: not of it.
        if (rule->too_fast_type.empty()) {
          tr.suppressed = true;
          ++out.class_decisions.suppressed_too_fast;
        } else {
          tr.relabelled_as = rule->too_fast_type;
          ++out.class_decisions.relabelled_too_fast;
        }
      }
    }
    Association& a = out.associations[v];
    if (!tr.relabelled_as.empty()) {
      a.box_lidar.type = a.box_world.type = tr.relabelled_as;
      tr.last_box.type = tr.relabelled_as;
      a.relabelled = true;
    }
    a.suppressed = tr.suppressed;
  }
}

}  // namespace dlslot::tracker
