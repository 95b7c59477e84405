#include "evaluation.hpp"

#include <algorithm>
#include <cstdio>
#include <stdexcept>

#include "velocity.hpp"

namespace dlslot::eval {

std::string primarySource(const std::map<std::string, Trajectory>& sources) {
  if (sources.count("slot")) return "slot";
  if (sources.count("odometry")) return "odometry";
  return sources.empty() ? "" : sources.begin()->first;
}

namespace {

// Labels and tracks get velocities the same way, in the world when both sides have poses,
// else relative to the sensor. Returns how they were compared, for the report.
std::string assignVelocities(RunData& run, double dynamic_speed_mps, double label_half_span_s) {
  auto& frames = run.tracking;
  const bool truth_world = std::all_of(frames.begin(), frames.end(), [](const TrackingFrame& f) { return f.truth_pose.has_value(); });
  const bool tracks_world = run.track_velocities_given ||
                            std::all_of(frames.begin(), frames.end(), [](const TrackingFrame& f) { return f.ego_pose.has_value(); });
  char speed[32], span[96];
  std::snprintf(speed, sizeof speed, "%g", dynamic_speed_mps);
  if (label_half_span_s > 0)
    std::snprintf(span, sizeof span, "central differences over +-%g s of the labelled positions", label_half_span_s);
  else
    std::snprintf(span, sizeof span, "differences of consecutive labelled positions");
  std::string how;
  if (truth_world && tracks_world) {
    finiteDifferenceVelocities(frames, Side::Truth, VelocityFrame::World, true, label_half_span_s);
    finiteDifferenceVelocities(frames, Side::Tracks, VelocityFrame::World, false);
    markDynamicLabels(frames, VelocityFrame::World, dynamic_speed_mps);
    how = "world frame (velocity over ground, compared in each scan's lidar axes); labels: " + std::string(span) +
          " put in the world with the ground-truth poses; tracks: " +
          std::string(run.track_velocities_given ? "the system's own velocity estimates"
                                                 : "differences of positions put in the world with the system's poses") +
          "; dynamic = labels whose mean speed over their life is >= " + speed + " m/s";
  } else {
    finiteDifferenceVelocities(frames, Side::Truth, VelocityFrame::Sensor, true, label_half_span_s);
    finiteDifferenceVelocities(frames, Side::Tracks, VelocityFrame::Sensor, true);
    markDynamicLabels(frames, VelocityFrame::Sensor, dynamic_speed_mps);
    how = "sensor frame (no ground-truth poses): velocity relative to the sensor; labels: " + std::string(span) +
          " in the lidar frames; tracks: differences of consecutive positions; every matched label counts";
  }
  return how;
}

TrackingMetrics trackingMetrics(std::vector<TrackingFrame> frames, const MatchCriterion& criterion) {
  dropIgnoredTracks(frames, criterion);
  TrackingMetrics t{criterion, evaluateClearMot(frames, criterion), evaluateHota(frames, criterion), {}};
  t.velocity_groups = breakdownVelocityErrors(t.clear.velocities, static_cast<int>(frames.size()));
  return t;
}

}  // namespace

Metrics evaluate(RunData run, const EvalOptions& options) {
  Metrics m;
  m.primary_source = primarySource(run.sources);
  for (const auto& [name, trajectory] : run.sources) {
    if (!run.truth) {
      m.ego[name] = std::nullopt;
      continue;
    }
    const auto [est, gt] = commonFrames(trajectory, inWorldOf(*run.truth, trajectory));
    if (est.empty())
      throw std::invalid_argument("the '" + name + "' trajectory (" + std::to_string(trajectory.size()) +
                                  " poses) and the ground truth share no frame");
    if (est.size() < trajectory.size())
      m.notes.push_back("source '" + name + "': " + std::to_string(trajectory.size() - est.size()) +
                        " poses have no ground truth and were not evaluated");
    m.ego[name] = evaluateEgo(est, gt);
  }
  if (run.has_labels && run.has_tracks) {
    restrictClasses(run.tracking, options.classes);
    m.label_velocity_half_span_s = options.label_velocity_half_span_s >= 0 ? options.label_velocity_half_span_s
                                                                            : labelVelocityHalfSpan(run.tracking);
    m.velocity_frame = assignVelocities(run, options.dynamic_speed_mps, m.label_velocity_half_span_s);
    m.tracking = trackingMetrics(run.tracking, options.distance);
    m.tracking_iou = trackingMetrics(run.tracking, options.iou);
    for (const auto& [cls, name] : {std::pair{"car", "Car"}, {"pedestrian", "Pedestrian"}, {"cyclist", "Cyclist"}}) {
      std::vector<TrackingFrame> frames = run.tracking;
      restrictClasses(frames, {name});
      if (std::none_of(frames.begin(), frames.end(), [](const TrackingFrame& f) { return !f.truth.empty(); })) continue;
      dropIgnoredTracks(frames, options.distance);
      m.tracking_by_class[cls] = evaluateClearMot(frames, options.distance);
    }
  }
  if (run.kitti) m.kitti = evaluateKittiTracking({*run.kitti}, options.kitti);
  m.timing_ms = std::move(run.timing_ms);
  m.frame_counts = std::move(run.frame_counts);
  m.frames = std::move(run.frames);
  m.memory = std::move(run.memory);
  m.registration = std::move(run.registration);
  m.odometry_checks = std::move(run.odometry_checks);
  m.map = std::move(run.map);
  m.notes.insert(m.notes.end(), run.notes.begin(), run.notes.end());
  return m;
}

}  // namespace dlslot::eval
