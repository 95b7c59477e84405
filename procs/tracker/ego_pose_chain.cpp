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

  const Pose* last_delta = nullptr;
  for (int f = from + 1; f <= frame; ++f) {
    auto d = odometry_delta_.find(f);
    if (d != odometry_delta_.end()) {
      last_delta = &d->second;
    } else {
      out.source = PoseSource::Predicted;
      if (!last_delta) {
        // No motion seen since the chain's start: take the one that led to it, if known.
        auto before = odometry_delta_.find(from);
        if (before == odometry_delta_.end()) continue;  // standing still is the only guess
        last_delta = &before->second;
      }
    }
    out.X = out.X * *last_delta;
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
