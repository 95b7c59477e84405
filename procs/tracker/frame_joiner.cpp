#include "frame_joiner.hpp"

namespace dlslot::tracker {

FrameJoiner::Pending& FrameJoiner::pending(int frame, int64_t utime, double now_s) {
  auto [it, inserted] = pending_.try_emplace(frame);
  if (inserted) {
    it->second.joined.frame = frame;
    it->second.joined.utime = utime;
    it->second.first_seen_s = now_s;
  }
  return it->second;
}

bool FrameJoiner::addDetections(int frame, DetectionFrame detections, double now_s) {
  if (frame <= last_released_) return false;
  Pending& p = pending(frame, detections.utime, now_s);
  p.joined.utime = detections.utime;  // the scan's own timestamp wins
  p.joined.detections = std::move(detections);
  return true;
}

bool FrameJoiner::addOdometry(int frame, int64_t utime, double now_s) {
  if (frame <= last_released_) return false;
  pending(frame, utime, now_s).joined.has_odometry = true;
  return true;
}

std::vector<JoinedFrame> FrameJoiner::release(double now_s) {
  // The newest complete scan: every scan before it is released now, complete or not.
  int newest_complete = -1;
  for (const auto& [frame, p] : pending_)
    if (p.joined.detections && p.joined.has_odometry) newest_complete = frame;

  std::vector<JoinedFrame> out;
  while (!pending_.empty()) {
    auto it = pending_.begin();
    const bool complete = it->second.joined.detections && it->second.joined.has_odometry;
    const bool expired = now_s - it->second.first_seen_s >= timeout_s_;
    if (!complete && !expired && it->first > newest_complete) break;
    it->second.joined.timed_out = !complete;
    out.push_back(std::move(it->second.joined));
    last_released_ = it->first;
    pending_.erase(it);
  }
  return out;
}

void FrameJoiner::reset() {
  pending_.clear();
  last_released_ = -1;
}

}  // namespace dlslot::tracker
