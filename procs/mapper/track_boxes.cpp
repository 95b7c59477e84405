#include "mapper/track_boxes.hpp"

#include <cmath>

namespace dlslot::mapper {

TrackBoxes::TrackBoxes(double margin_m, int follow_frames, bool movable, double clearance_m)
    : margin_(margin_m), clearance_(clearance_m), follow_(follow_frames), movable_(movable) {}

void TrackBoxes::add(int frame, double stamp_s, const std::vector<TrackSnapshot>& tracks) {
  for (const TrackSnapshot& t : tracks) {
    History& h = tracks_[t.id];
    h.ever_dynamic = h.ever_dynamic || t.dynamic;
    // A coasting track's box is the backend's prediction: the sightings around the gap give a
    // better one (interpolation), so only observed boxes are kept.
    if (t.observed) h.seen[frame] = Sighting{stamp_s, t.box, t.velocity};
  }
}

std::vector<Box> TrackBoxes::removalBoxes(int frame, double stamp_s) const {
  std::vector<Box> out;
  for (const auto& [id, h] : tracks_) {
    if (!(h.ever_dynamic || movable_) || h.seen.empty()) continue;
    auto after = h.seen.lower_bound(frame);
    std::optional<Box> box;
    if (after != h.seen.end() && after->first == frame) {
      box = after->second.box;
    } else {
      const bool has_after = after != h.seen.end() && after->first - frame <= follow_;
      const bool has_before = after != h.seen.begin() && frame - std::prev(after)->first <= follow_;
      if (has_before && has_after) {  // between two sightings: linear in time
        const Sighting& a = std::prev(after)->second;
        const Sighting& b = after->second;
        const double s = b.stamp > a.stamp ? (stamp_s - a.stamp) / (b.stamp - a.stamp) : 0.5;
        Box m = a.box;
        m.center = (1 - s) * a.box.center + s * b.box.center;
        m.yaw = a.box.yaw + s * wrapAngle(b.box.yaw - a.box.yaw);
        box = m;
      } else if (has_before || has_after) {  // before the first or after the last sighting: its velocity
        const Sighting& a = has_before ? std::prev(after)->second : after->second;
        Box m = a.box;
        m.center += a.velocity * (stamp_s - a.stamp);
        box = m;
      }
    }
    if (!box) continue;
    // Grown by the margin on every side but the bottom, which is raised by the clearance.
    box->size += Eigen::Vector3d(2 * margin_, 2 * margin_, margin_ - clearance_);
    box->center.z() += 0.5 * (margin_ + clearance_);
    box->id = id;
    out.push_back(*box);
  }
  return out;
}

void TrackBoxes::forgetBefore(int frame) {
  for (auto it = tracks_.begin(); it != tracks_.end();) {
    History& h = it->second;
    h.seen.erase(h.seen.begin(), h.seen.lower_bound(frame - follow_));
    it = h.seen.empty() ? tracks_.erase(it) : std::next(it);
  }
}

}  // namespace dlslot::mapper
