#include "run_state.hpp"

#include <algorithm>
#include <limits>

namespace dlslot::renderer {

RunState::RunState(int max_pending_frames, int trail_frames)
    : max_pending_(std::max(1, max_pending_frames)), trail_frames_(std::max(0, trail_frames)) {}

RunState::Pending* RunState::pendingFrame(int frame, int64_t utime) {
  if (!first_utime_) first_utime_ = utime;
  newest_frame_ = std::max(newest_frame_, frame);
  if (frame <= last_drawn_) {
    ++late_;
    return nullptr;
  }
  Pending& p = pending_[frame];
  if (p.input.frame < 0) {
    p.input.frame = frame;
    p.utime = utime;
  }
  return &p;
}

bool RunState::addScan(int frame, int64_t utime, PointCloud scan) {
  Pending* p = pendingFrame(frame, utime);
  if (!p) return false;
  p->utime = utime;  // the scan's timestamp is the frame's
  p->input.has_scan = true;
  p->input.scan = std::move(scan);
  return true;
}

bool RunState::addDetections(int frame, int64_t utime, std::vector<Box> detections) {
  Pending* p = pendingFrame(frame, utime);
  if (!p) return false;
  p->input.has_detections = true;
  p->input.detections = std::move(detections);
  return true;
}

bool RunState::addGroundTruth(int frame, int64_t utime, const std::optional<Pose>& T_world_lidar,
                              std::vector<Box> boxes) {
  if (T_world_lidar) gt_poses_[frame] = *T_world_lidar;
  Pending* p = pendingFrame(frame, utime);
  if (!p) return false;
  p->input.has_ground_truth = true;
  p->input.gt_boxes = std::move(boxes);
  return true;
}

bool RunState::addOdometry(int frame, int64_t utime, const Pose& T_world_lidar, bool filtered, int points_removed,
                           ModuleTiming timing) {
  odometry_poses_[frame] = T_world_lidar;
  Pending* p = pendingFrame(frame, utime);
  if (!p) return false;
  p->input.has_odometry = true;
  p->input.odometry_filtered = filtered;
  p->input.odometry_removed = points_removed;
  p->input.timings.push_back(std::move(timing));
  return true;
}

bool RunState::addAssociations(int frame, int64_t utime, std::vector<AssociationMark> marks, ModuleTiming timing) {
  Pending* p = pendingFrame(frame, utime);
  if (!p) return false;
  p->input.has_associations = true;
  p->input.associations = std::move(marks);
  p->input.timings.push_back(std::move(timing));
  return true;
}

bool RunState::addSlotState(int frame, int64_t utime, SlotStateData state) {
  slot_poses_[frame] = state.ego_pose;
  if (state.smoothed_frame) smoothed_[*state.smoothed_frame] = {frame, state.smoothed_pose};
  for (const TrackState& t : state.tracks) {
    TrackHistory& h = tracks_[t.id];
    h.path.id = t.id;
    h.path.type = t.type;
    h.path.is_dynamic = t.is_dynamic;
    h.path.last_pose = t.pose;
    h.path.size = t.size;
    if (!h.frames.empty() && h.frames.back() >= frame) continue;  // a repeated SLOT_STATE
    h.path.positions.push_back(t.pose.translation());
    h.frames.push_back(frame);
  }
  Pending* p = pendingFrame(frame, utime);
  if (!p) return false;
  p->input.has_tracks = true;
  p->input.slot_mode = state.mode;
  p->input.tracks = std::move(state.tracks);
  p->input.timings.push_back(std::move(state.timing));
  return true;
}

Pose RunState::slotPoseAsOf(int frame, int as_of) const {
  auto s = smoothed_.find(frame);
  if (s != smoothed_.end() && s->second.delivered_at <= as_of) return s->second.pose;
  return slot_poses_.at(frame);
}

RenderInput RunState::finish(int frame, Pending&& p) {
  RenderInput in = std::move(p.input);
  in.frame = frame;
  in.utime = p.utime;
  in.time_s = 1e-6 * static_cast<double>(p.utime - first_utime_.value_or(p.utime));

  // Trajectories as known when this frame was processed: nothing from later frames.
  for (auto it = odometry_poses_.begin(); it != odometry_poses_.end() && it->first <= frame; ++it)
    in.odometry_path.push_back(it->second.translation());
  for (auto it = gt_poses_.begin(); it != gt_poses_.end() && it->first <= frame; ++it)
    in.gt_path.push_back(it->second.translation());
  for (auto it = slot_poses_.begin(); it != slot_poses_.end() && it->first <= frame; ++it)
    in.slot_path.push_back(slotPoseAsOf(it->first, frame).translation());

  if (auto s = slot_poses_.find(frame); s != slot_poses_.end()) {
    in.ego_pose = s->second;
    in.ego_source = "DL-SLOT";
  } else if (auto o = odometry_poses_.find(frame); o != odometry_poses_.end()) {
    in.ego_pose = o->second;
    in.ego_source = "odometry";
  } else if (auto g = gt_poses_.find(frame); g != gt_poses_.end()) {
    in.ego_pose = g->second;
    in.ego_source = "ground truth";
  }

  for (TrackState& t : in.tracks) {
    auto h = tracks_.find(t.id);
    if (h == tracks_.end()) continue;
    const auto& frames = h->second.frames;
    for (size_t i = 0; i < frames.size(); ++i)
      if (frames[i] < frame && frames[i] >= frame - trail_frames_) t.trail.push_back(h->second.path.positions[i]);
  }
  // Module order fixed by the pipeline, whatever order the messages came in.
  auto rank = [](const std::string& m) { return m == "odometry" ? 0 : m == "tracker" ? 1 : m == "backend" ? 2 : 3; };
  std::stable_sort(in.timings.begin(), in.timings.end(),
                   [&](const ModuleTiming& a, const ModuleTiming& b) { return rank(a.module) < rank(b.module); });

  last_drawn_ = std::max(last_drawn_, frame);
  last_utime_ = std::max(last_utime_, p.utime);
  ++frames_drawn_;
  if (!in.has_tracks) ++frames_without_slot_;
  return in;
}

std::vector<RenderInput> RunState::takeReady() {
  // Everything up to the newest frame with a SLOT_STATE, and frames overtaken by newer data.
  int ready_up_to = newest_frame_ - max_pending_;
  for (const auto& [frame, p] : pending_)
    if (p.input.has_tracks) ready_up_to = std::max(ready_up_to, frame);
  std::vector<RenderInput> out;
  while (!pending_.empty() && pending_.begin()->first <= ready_up_to) {
    auto node = pending_.extract(pending_.begin());
    out.push_back(finish(node.key(), std::move(node.mapped())));
  }
  return out;
}

std::vector<RenderInput> RunState::takeAll() {
  std::vector<RenderInput> out;
  while (!pending_.empty()) {
    auto node = pending_.extract(pending_.begin());
    out.push_back(finish(node.key(), std::move(node.mapped())));
  }
  return out;
}

RunSummary RunState::summary() const {
  RunSummary s;
  s.frames_rendered = frames_drawn_;
  auto extend = [&s](int f) {
    s.first_frame = s.first_frame < 0 ? f : std::min(s.first_frame, f);
    s.last_frame = std::max(s.last_frame, f);
  };
  for (const auto& [f, T] : odometry_poses_) s.odometry_path[f] = T.translation(), extend(f);
  for (const auto& [f, T] : gt_poses_) s.gt_path[f] = T.translation(), extend(f);
  for (const auto& [f, T] : slot_poses_) s.slot_path[f] = slotPoseAsOf(f, std::numeric_limits<int>::max()).translation(), extend(f);
  s.duration_s = first_utime_ ? 1e-6 * static_cast<double>(last_utime_ - *first_utime_) : 0.0;
  for (const auto& [id, h] : tracks_) s.tracks.push_back(h.path);
  return s;
}

}  // namespace dlslot::renderer
