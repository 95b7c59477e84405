#include "velocity.hpp"

#include <algorithm>
#include <map>
#include <stdexcept>

namespace dlslot::eval {
namespace {

std::vector<Object>& objects(TrackingFrame& f, Side side) { return side == Side::Truth ? f.truth : f.tracks; }

const std::optional<Pose>& poseOf(const TrackingFrame& f, Side side) {
  return side == Side::Truth ? f.truth_pose : f.ego_pose;
}

}  // namespace

void finiteDifferenceVelocities(std::vector<TrackingFrame>& frames, Side side, VelocityFrame velocity_frame,
                                bool overwrite, double half_span_s) {
  const bool world = velocity_frame == VelocityFrame::World;
  // Position of every object by frame and id, in the frame the differences are taken in.
  std::vector<std::map<int, Eigen::Vector3d>> positions(frames.size());
  for (size_t t = 0; t < frames.size(); ++t) {
    const std::optional<Pose>& pose = poseOf(frames[t], side);
    if (world && !pose)
      throw std::invalid_argument("world-frame velocities need a pose for frame " + std::to_string(frames[t].frame));
    for (const Object& o : objects(frames[t], side))
      positions[t][o.box.id] = world ? Eigen::Vector3d(*pose * o.box.center) : o.box.center;
  }
  for (size_t t = 0; t < frames.size(); ++t) {
    for (Object& o : objects(frames[t], side)) {
      if (o.velocity && !overwrite) continue;
      // The widest symmetric span within half_span_s whose ends saw the object; else the
      // neighbours that saw it (a missing side makes it one-sided).
      size_t a = t, b = t;
      for (size_t k = 1; k <= t && t + k < frames.size(); ++k) {
        const double half = std::max(frames[t].stamp - frames[t - k].stamp, frames[t + k].stamp - frames[t].stamp);
        if (half > half_span_s + 1e-9) break;
        if (positions[t - k].count(o.box.id) && positions[t + k].count(o.box.id)) a = t - k, b = t + k;
      }
      if (a == b) {
        if (t > 0 && positions[t - 1].count(o.box.id)) a = t - 1;
        if (t + 1 < frames.size() && positions[t + 1].count(o.box.id)) b = t + 1;
      }
      const double dt = frames[b].stamp - frames[a].stamp;
      if (a == b || !(dt > 0)) {
        o.velocity.reset();
        continue;
      }
      Eigen::Vector3d v = (positions[b].at(o.box.id) - positions[a].at(o.box.id)) / dt;
      if (world) v = poseOf(frames[t], side)->linear().transpose() * v;
      o.velocity = v.head<2>();
    }
  }
}

double labelVelocityHalfSpan(const std::vector<TrackingFrame>& frames) {
  for (const TrackingFrame& f : frames)
    for (const Object& o : f.truth)
      if (o.box.center.x() < 0) return 0.0;
  return 0.5;
}

void markDynamicLabels(std::vector<TrackingFrame>& frames, VelocityFrame velocity_frame, double min_speed_mps) {
  if (velocity_frame == VelocityFrame::Sensor) {
    for (TrackingFrame& f : frames)
      for (Object& o : f.truth) o.dynamic = o.velocity.has_value();
    return;
  }
  // First and last sighting of every label in the world: the mean speed over its whole life is
  // robust to the frame-to-frame jitter of real labels, which alone reaches 0.5 m/s at 10 Hz.
  struct Span {
    double t0 = 0, t1 = 0;
    Eigen::Vector3d p0, p1;
    bool seen = false;
  };
  std::map<int, Span> spans;
  for (const TrackingFrame& f : frames)
    for (const Object& o : f.truth) {
      if (!f.truth_pose) throw std::invalid_argument("world-frame motion needs a pose for frame " + std::to_string(f.frame));
      const Eigen::Vector3d p = *f.truth_pose * o.box.center;
      Span& s = spans[o.box.id];
      if (!s.seen) {
        s.t0 = f.stamp;
        s.p0 = p;
        s.seen = true;
      }
      s.t1 = f.stamp;
      s.p1 = p;
    }
  for (TrackingFrame& f : frames)
    for (Object& o : f.truth) {
      const Span& s = spans.at(o.box.id);
      o.dynamic = o.velocity && s.t1 > s.t0 && (s.p1 - s.p0).norm() / (s.t1 - s.t0) >= min_speed_mps;
    }
}

}  // namespace dlslot::eval
