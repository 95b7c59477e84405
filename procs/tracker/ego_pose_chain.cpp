#include "ego_pose_chain.hpp"

#include <iterator>

namespace dlslot::tracker {

const char* poseSourceName(PoseSource s) {
  switch (s) {
    case PoseSource::Slot: return "slot";
    case PoseSource::Odometry: return "odometry";
    case PoseSource::Predicted: return "predicted";
  }
  return "?";
}

void EgoPoseChain::addOptimized(int frame, const Pose& X) { optimized_[frame] = X; }

void EgoPoseChain::addOdometry(int frame, const Pose& pose, const Pose& delta) {
  odometry_pose_[frame] = pose;
  odometry_delta_[frame] = delta;
}

EgoPose EgoPoseChain::poseAt(int frame) const {
  if (auto it = optimized_.find(frame); it != optimized_.end()) return {it->second, PoseSource::Slot};

  // Start of the chain: the newest optimized pose before `frame`; without one, the odometry's
  // own pose (itself a chain of its deltas from the first scan) at the newest scan it has.
  EgoPose out;
  int from = 0;
  auto opt = optimized_.lower_bound(frame);
  if (opt != optimized_.begin()) {
    --opt;
    from = opt->first;
    out = {opt->second, PoseSource::Odometry};
  } else {
    auto odo = odometry_pose_.upper_bound(frame);
    if (odo == odometry_pose_.begin()) return out;  // nothing known yet: identity, predicted
    --odo;
    from = odo->first;
    out = {odo->second, PoseSource::Odometry};
  }

  // T_f^{f+1} * ... * T_{t-1}^t from the deltas. A scan the odometry never saw (a frame gap)
  // leaves a hole: its own poses still give the motion, X_t = X_f * inv(O_f) * O_t.
  // (64-bit loop counters: with frame == INT32_MAX an int counter would never pass it.)
  bool complete = true;
  for (int64_t f = int64_t{from} + 1; f <= frame && complete; ++f) complete = odometry_delta_.count(static_cast<int>(f)) > 0;
  if (complete) {
    for (int64_t f = int64_t{from} + 1; f <= frame; ++f) out.X = out.X * odometry_delta_.at(static_cast<int>(f));
    return out;
  }
  auto o_from = odometry_pose_.find(from), o_to = odometry_pose_.find(frame);
  if (o_from != odometry_pose_.end() && o_to != odometry_pose_.end()) {
    out.X = out.X * o_from->second.inverse() * o_to->second;
    return out;
  }
  // The odometry of this scan is missing: repeat the last motion known (constant velocity).
  out.source = PoseSource::Predicted;
  const Pose* last_delta = nullptr;
  if (auto before = odometry_delta_.find(from); before != odometry_delta_.end()) last_delta = &before->second;
  for (int64_t f = int64_t{from} + 1; f <= frame; ++f) {
    if (auto d = odometry_delta_.find(static_cast<int>(f)); d != odometry_delta_.end()) last_delta = &d->second;
    if (last_delta) out.X = out.X * *last_delta;  // with no motion known, standing still
  }
  return out;
}

void EgoPoseChain::forgetBefore(int frame) {
  auto opt = optimized_.lower_bound(frame);
  if (opt != optimized_.begin()) optimized_.erase(optimized_.begin(), std::prev(opt));
  // Deltas are chained from the oldest optimized pose kept, and one before it for prediction.
  const int keep_from = optimized_.empty() ? frame : std::min(frame, optimized_.begin()->first);
  odometry_pose_.erase(odometry_pose_.begin(), odometry_pose_.lower_bound(keep_from - 1));
  odometry_delta_.erase(odometry_delta_.begin(), odometry_delta_.lower_bound(keep_from - 1));
}

}  // namespace dlslot::tracker
