#include "scan_joiner.hpp"

namespace dlslot::odometry {

ScanJoiner::Pending& ScanJoiner::pending(int frame, double now_s) {
  auto [it, inserted] = pending_.try_emplace(frame);
  if (inserted) it->second.first_seen_s = now_s;
  return it->second;
}

bool ScanJoiner::addScan(int frame, int64_t utime, PointCloud scan, double now_s) {
  if (frame <= last_released_) return false;
  Pending& p = pending(frame, now_s);
  p.scan.emplace();
  p.scan->index = frame;
  p.scan->utime = utime;
  p.scan->scan = std::move(scan);
  return true;
}

bool ScanJoiner::addDetections(int frame, std::vector<Box> boxes, double now_s) {
  if (frame <= last_released_) return false;
  pending(frame, now_s).boxes = std::move(boxes);
  return true;
}

std::vector<JoinedScan> ScanJoiner::release(double now_s) {
  auto complete = [this](const Pending& p) { return p.scan && (p.boxes || !need_detections_); };
  int newest_complete = -1;
  for (const auto& [frame, p] : pending_)
    if (complete(p)) newest_complete = frame;

  std::vector<JoinedScan> out;
  while (!pending_.empty()) {
    auto it = pending_.begin();
    Pending& p = it->second;
    const bool expired = now_s - p.first_seen_s >= timeout_s_;
    if (!complete(p) && !expired && it->first > newest_complete) break;
    if (p.scan) {
      JoinedScan j;
      j.frame = std::move(*p.scan);
      j.has_detections = p.boxes.has_value();
      if (p.boxes) j.frame.detections = std::move(*p.boxes);
      out.push_back(std::move(j));
      last_released_ = it->first;
    }
    pending_.erase(it);
  }
  return out;
}

void ScanJoiner::reset() {
  pending_.clear();
  last_released_ = -1;
}

}  // namespace dlslot::odometry
