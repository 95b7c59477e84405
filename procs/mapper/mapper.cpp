#include "mapper/mapper.hpp"

#include <cmath>
#include <memory>

#include "dlslot/cpu_clock.hpp"
#include "mapper/box_cutter.hpp"

namespace dlslot::mapper {

Mapper::Mapper(const MapperConfig& config, bool threaded)
    : config_(config),
      boxes_(config.box_margin_m, config.follow_frames, config.remove_movable, config.ground_clearance_m),
      map_(config.map_voxel_m),
      removed_(config.map_voxel_m),
      loops_(std::make_unique<LoopCloser>(config.loop, config.lidar, threaded, static_cast<size_t>(config.max_backlog_keyframes),
                                          config.idle_priority, config.live_cpu_share)),
      // Every keyframe admitted while the backlog was below the bound must fit without blocking the
      // caller: those still in their decision delay (one per scan at most) come on top of the bound.
      committer_(std::make_unique<IdleWorker>(
          "keyframes", threaded,
          static_cast<size_t>(config.max_backlog_keyframes) + static_cast<size_t>(config.decision_delay_frames) + 2,
          config.idle_priority, config.live_cpu_share)) {}

Mapper::~Mapper() {
  // The keyframe thread uses the loop closer: it stops first.
  committer_.reset();
  loops_.reset();
}

bool Mapper::needsScan(const Pose& pose) const {
  if (!last_keyframe_pose_) return true;
  const Pose d = last_keyframe_pose_->inverse() * pose;
  return d.translation().norm() >= config_.keyframe_distance_m ||
         Eigen::AngleAxisd(d.rotation()).angle() * 180.0 / M_PI >= config_.keyframe_angle_deg;
}

void Mapper::add(MapperInput in) {
  frames_[in.frame] = {in.utime, in.pose};
  boxes_.add(in.frame, in.utime * 1e-6, in.tracks);
  if (needsScan(in.pose)) {
    if (committer_->backlog() >= static_cast<size_t>(config_.max_backlog_keyframes)) {
      // The keyframe thread is behind (no idle time on the machine): this scan is not taken; the
      // next one is considered again, so keyframes grow further apart instead of the queue.
      ++deferred_;
    } else {
      last_keyframe_pose_ = in.pose;
      pending_.push_back({in.frame, in.utime, in.pose, std::move(in.scan), std::move(in.load_scan)});
      last_scan_.reset();
    }
  }
  // One raw scan not taken is held: the run's last one becomes a keyframe in finish().
  if (pending_.empty() || pending_.back().frame != in.frame)
    last_scan_ = Pending{in.frame, in.utime, in.pose, std::move(in.scan), std::move(in.load_scan), true};
  while (!pending_.empty() && pending_.front().frame <= in.frame - config_.decision_delay_frames) {
    auto job = std::make_shared<Pending>(std::move(pending_.front()));
    pending_.pop_front();
    // The removal boxes are decided here (the tracks' history lives on this thread); the points are
    // handled on the keyframe thread.
    auto boxes = std::make_shared<std::vector<MovingBox>>(lidarBoxes(*job));
    const BodyTwist twist = egoTwist(*job);
    committer_->post([this, job, boxes, twist] { commit(*job, *boxes, twist); });
  }
  boxes_.forgetBefore(pending_.empty() ? in.frame - config_.decision_delay_frames : pending_.front().frame);
}

std::vector<MovingBox> Mapper::lidarBoxes(const Pending& p) const {
  // The boxes in the keyframe's lidar frame, and in the lidar frames of the scans before and after
  // it: their difference is each object's motion relative to the lidar (its own and the ego's),
  // which places it at the firing time of each point (sweep_timing.hpp).
  const auto inLidar = [&](int frame, int64_t utime, const Pose& pose) {
    std::map<int, Box> out;
    const Pose lidar_from_world = pose.inverse();
    for (const Box& b : boxes_.removalBoxes(frame, utime * 1e-6)) out[b.id] = b.transformed(lidar_from_world);
    return out;
  };
  // A neighbouring scan's time and boxes (none when that scan is not held).
  const auto neighbour = [&](int frame) -> std::pair<int64_t, std::map<int, Box>> {
    const auto it = frames_.find(frame);
    if (it == frames_.end()) return {p.utime, {}};
    return {it->second.first, inLidar(frame, it->second.first, it->second.second)};
  };
  const auto [t_before, before] = neighbour(p.frame - 1);
  const auto [t_after, after] = neighbour(p.frame + 1);
  std::vector<MovingBox> out;
  for (const auto& [id, b] : inLidar(p.frame, p.utime, p.pose)) {
    // Seen in only one of the neighbours: the motion over that half; in neither: still.
    const auto a = before.find(id), c = after.find(id);
    const bool has_a = a != before.end(), has_c = c != after.end();
    out.push_back(movingBox(b, has_a ? a->second : b, has_c ? c->second : b,
                            ((has_c ? t_after : p.utime) - (has_a ? t_before : p.utime)) * 1e-6));
  }
  return out;
}

BodyTwist Mapper::egoTwist(const Pending& p) const {
  // Central difference over the scans before and after (one-sided at the ends of the run): the
  // SLOT poses are for each scan's reference instant, 0.1 s apart, so their twist is the sweep's.
  const auto pose = [&](int frame) -> std::optional<std::pair<int64_t, Pose>> {
    const auto it = frames_.find(frame);
    if (it == frames_.end()) return std::nullopt;
    return it->second;
  };
  const auto before = pose(p.frame - 1), after = pose(p.frame + 1);
  const std::pair<int64_t, Pose> here{p.utime, p.pose};
  const auto& a = before ? *before : here;
  const auto& b = after ? *after : here;
  return twistBetween(a.second, b.second, (b.first - a.first) * 1e-6);
}

void Mapper::finish() {
  if (last_scan_) {
    pending_.push_back(std::move(*last_scan_));
    last_scan_.reset();
  }
  while (!pending_.empty()) {
    auto job = std::make_shared<Pending>(std::move(pending_.front()));
    pending_.pop_front();
    auto boxes = std::make_shared<std::vector<MovingBox>>(lidarBoxes(*job));
    const BodyTwist twist = egoTwist(*job);
    committer_->post([this, job, boxes, twist] { commit(*job, *boxes, twist); });
  }
  // The keyframe thread's catch-up feeds the loop thread: both at full speed from here.
  loops_->worker().liftLimits();
  committer_->drain();
  loops_->drain();
  applyLoopResult();
}

MapperSnapshot Mapper::snapshot() const {
  MapperSnapshot s;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    s.map_from_world = map_from_world_;
  }
  s.keyframes = keyframe_count_;
  s.map_voxels = map_voxels_;
  s.removed_voxels = removed_voxels_;
  s.keyframes_deferred = deferred_;
  s.backlog = committer_->backlog();
  return s;
}

Pose Mapper::mapFromWorld() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return map_from_world_;
}

std::vector<ScanRefused> Mapper::takeRefusedScans() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<ScanRefused> out;
  out.swap(refused_);
  return out;
}

std::vector<std::string> Mapper::priorityErrors() const {
  std::vector<std::string> out;
  for (const IdleWorker* w : {committer_.get(), &loops_->worker()})
    if (!w->priorityError().empty()) out.push_back(w->priorityError());
  return out;
}

std::vector<std::string> Mapper::takeErrors() {
  std::vector<std::string> out = committer_->takeErrors();
  for (std::string& e : loops_->worker().takeErrors()) out.push_back(std::move(e));
  return out;
}

void Mapper::commit(Pending& p, const std::vector<MovingBox>& boxes, const BodyTwist& twist) {
  // CPU time of this thread: at idle priority the wall time mostly counts waiting for a core.
  const double start = threadCpuMs();
  PointCloud scan;
  if (p.load_scan) {
    try {
      scan = p.load_scan();
    } catch (const ScanRefused& e) {
      std::lock_guard<std::mutex> lock(mutex_);
      refused_.push_back(e);
      return;
    }
    p.load_scan = nullptr;  // frees the raw message
  } else {
    scan.swap(p.scan);
  }
  // Crop to [min_range, max_range] in place.
  Eigen::Index n = 0;
  const float lo = static_cast<float>(config_.min_range_m * config_.min_range_m),
              hi = static_cast<float>(config_.max_range_m * config_.max_range_m);
  for (Eigen::Index i = 0; i < scan.cols(); ++i) {
    const float r2 = scan.col(i).head<3>().squaredNorm();
    if (r2 >= lo && r2 <= hi) {
      if (n != i) scan.col(n) = scan.col(i);
      ++n;
    }
  }
  // The removal test (box_cutter.hpp), each box where it was at each point's firing time.
  const BoxCutter cutter(boxes, config_.max_range_m, config_.lidar.sweep);
  PointCloud kept(4, n), gone(4, n);
  Eigen::Index nk = 0, ng = 0;
  for (Eigen::Index i = 0; i < n; ++i) (cutter.inside(scan.col(i).head<3>()) ? gone.col(ng++) : kept.col(nk++)) = scan.col(i);
  kept.conservativeResize(4, nk);
  gone.conservativeResize(4, ng);
  const int id = static_cast<int>(keyframes_.size());
  const Pose T_map = mapFromWorld() * p.pose;
  const size_t fresh = map_.insert(id, T_map, kept);
  removed_.insert(id, T_map, gone);
  keyframes_.push_back({p.frame, p.utime, p.pose, T_map, static_cast<int>(nk), static_cast<int>(ng), T_map});
  keyframe_count_ = static_cast<int>(keyframes_.size());
  map_voxels_ = map_.size();
  removed_voxels_ = removed_.size();
  keyframe_ms_ += threadCpuMs() - start;
  // Only a keyframe that saw something new keeps its registration cloud for later loops: one
  // that adds (almost) no voxel to the map is a place already held by earlier keyframes, so the
  // loop closer's memory, like the map's, stops growing when the map does (driving in circles,
  // standing in traffic).
  const bool keep_cloud = static_cast<double>(fresh) >= config_.min_new_fraction * static_cast<double>(std::max<Eigen::Index>(nk, 1));
  loops_->add({id, p.frame, p.pose, std::move(kept), twist, keep_cloud, p.last});
  applyLoopResult();
}

void Mapper::applyLoopResult() {
  std::optional<std::vector<Pose>> poses = loops_->takeOptimizedPoses();
  if (!poses || poses->empty()) return;
  optimized_ = std::move(*poses);
  const int last = static_cast<int>(optimized_.size()) - 1;
  const Pose correction = optimized_[last] * keyframes_.at(last).odometry.inverse();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    map_from_world_ = correction;
  }
  // Keyframes the loop closer has not seen yet follow the newest correction.
  std::vector<Pose> all(keyframes_.size());
  for (size_t k = 0; k < keyframes_.size(); ++k)
    all[k] = k < optimized_.size() ? optimized_[k] : correction * keyframes_[k].odometry;
  for (size_t k = 0; k < keyframes_.size(); ++k) keyframes_[k].map = all[k];
  map_.repose(all);
  removed_.repose(all);
  map_voxels_ = map_.size();
  removed_voxels_ = removed_.size();
}

std::vector<std::pair<int, Pose>> Mapper::mapTrajectory() const {
  std::vector<std::pair<int, Pose>> out;
  size_t k = 0;  // the newest keyframe at or before the frame
  for (const auto& [frame, tp] : frames_) {
    while (k + 1 < keyframes_.size() && keyframes_[k + 1].frame <= frame) ++k;
    Pose correction = mapFromWorld();
    if (!keyframes_.empty() && keyframes_[k].frame <= frame) correction = keyframes_[k].map * keyframes_[k].odometry.inverse();
    out.emplace_back(frame, correction * tp.second);
  }
  return out;
}

std::vector<int64_t> Mapper::frameUtimes() const {
  std::vector<int64_t> out;
  for (const auto& [frame, tp] : frames_) out.push_back(tp.first);
  return out;
}

}  // namespace dlslot::mapper
