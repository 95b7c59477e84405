#include "mapper/mapper.hpp"

#include <chrono>
#include <cmath>

namespace dlslot::mapper {

Mapper::Mapper(const MapperConfig& config, bool threaded)
    : config_(config),
      boxes_(config.box_margin_m, config.follow_frames, config.remove_movable, config.ground_clearance_m),
      map_(config.map_voxel_m),
      removed_(config.map_voxel_m),
      loops_(std::make_unique<LoopCloser>(config.loop, threaded)) {}

bool Mapper::needsScan(const Pose& pose) const {
  if (!last_keyframe_pose_) return true;
  const Pose d = last_keyframe_pose_->inverse() * pose;
  return d.translation().norm() >= config_.keyframe_distance_m ||
         Eigen::AngleAxisd(d.rotation()).angle() * 180.0 / M_PI >= config_.keyframe_angle_deg;
}

void Mapper::add(const MapperInput& in) {
  frames_[in.frame] = {in.utime, in.pose};
  boxes_.add(in.frame, in.utime * 1e-6, in.tracks);
  if (needsScan(in.pose)) {
    last_keyframe_pose_ = in.pose;
    Pending p{in.frame, in.utime, in.pose, PointCloud(4, in.scan.cols())};
    Eigen::Index n = 0;
    const double lo = config_.min_range_m * config_.min_range_m, hi = config_.max_range_m * config_.max_range_m;
    for (Eigen::Index i = 0; i < in.scan.cols(); ++i) {
      const double r2 = in.scan.col(i).head<3>().cast<double>().squaredNorm();
      if (r2 >= lo && r2 <= hi) p.scan.col(n++) = in.scan.col(i);
    }
    p.scan.conservativeResize(4, n);
    pending_.push_back(std::move(p));
  }
  while (!pending_.empty() && pending_.front().frame <= in.frame - config_.decision_delay_frames) {
    commit(pending_.front());
    pending_.pop_front();
  }
  boxes_.forgetBefore(pending_.empty() ? in.frame - config_.decision_delay_frames : pending_.front().frame);
  applyLoopResult();
}

void Mapper::finish() {
  while (!pending_.empty()) {
    commit(pending_.front());
    pending_.pop_front();
  }
  loops_->drain();
  applyLoopResult();
}

void Mapper::commit(Pending& p) {
  const auto start = std::chrono::steady_clock::now();
  const Pose lidar_from_world = p.pose.inverse();
  // The removal boxes in the lidar frame, with their heading's sine and cosine and the radius of
  // their footprint worked out once: the test runs for every point of the keyframe against every
  // box (Box::contains's test, in float, after a cheap footprint-circle rejection).
  struct Cut {
    Eigen::Vector3f center, half;
    float c, s, reach2;
  };
  std::vector<Cut> cuts;
  for (const Box& world_box : boxes_.removalBoxes(p.frame, p.utime * 1e-6)) {
    const Box b = world_box.transformed(lidar_from_world);
    const float reach = 0.5f * static_cast<float>(b.size.head<2>().norm());
    cuts.push_back({b.center.cast<float>(), 0.5f * b.size.cast<float>(), static_cast<float>(std::cos(b.yaw)),
                    static_cast<float>(std::sin(b.yaw)), reach * reach});
  }
  PointCloud kept(4, p.scan.cols()), gone(4, p.scan.cols());
  Eigen::Index nk = 0, ng = 0;
  for (Eigen::Index i = 0; i < p.scan.cols(); ++i) {
    bool inside = false;
    for (const Cut& k : cuts) {
      const Eigen::Vector3f d = p.scan.col(i).head<3>() - k.center;
      if (d.head<2>().squaredNorm() > k.reach2) continue;
      inside = std::abs(k.c * d.x() + k.s * d.y()) <= k.half.x() && std::abs(-k.s * d.x() + k.c * d.y()) <= k.half.y() &&
               std::abs(d.z()) <= k.half.z();
      if (inside) break;
    }
    (inside ? gone.col(ng++) : kept.col(nk++)) = p.scan.col(i);
  }
  kept.conservativeResize(4, nk);
  gone.conservativeResize(4, ng);
  const int id = static_cast<int>(keyframes_.size());
  const Pose T_map = map_from_world_ * p.pose;
  const size_t fresh = map_.insert(id, T_map, kept);
  removed_.insert(id, T_map, gone);
  keyframes_.push_back({p.frame, p.utime, p.pose, T_map, static_cast<int>(nk), static_cast<int>(ng)});
  keyframe_ms_ += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  // Only a keyframe that saw something new keeps its registration cloud for later loops: one
  // that adds (almost) no voxel to the map is a place already held by earlier keyframes, so the
  // loop closer's memory, like the map's, stops growing when the map does (driving in circles,
  // standing in traffic).
  const bool keep_cloud = static_cast<double>(fresh) >= config_.min_new_fraction * static_cast<double>(std::max<Eigen::Index>(nk, 1));
  loops_->add({id, p.frame, p.pose, std::move(kept), keep_cloud});
  p.scan.resize(4, 0);
}

void Mapper::applyLoopResult() {
  std::optional<std::vector<Pose>> poses = loops_->takeOptimizedPoses();
  if (!poses || poses->empty()) return;
  optimized_ = std::move(*poses);
  const int last = static_cast<int>(optimized_.size()) - 1;
  map_from_world_ = optimized_[last] * keyframes_.at(last).odometry.inverse();
  // Keyframes the loop closer has not seen yet follow the newest correction.
  std::vector<Pose> all(keyframes_.size());
  for (size_t k = 0; k < keyframes_.size(); ++k)
    all[k] = k < optimized_.size() ? optimized_[k] : map_from_world_ * keyframes_[k].odometry;
  for (size_t k = 0; k < keyframes_.size(); ++k) keyframes_[k].map = all[k];
  map_.repose(all);
  removed_.repose(all);
}

std::vector<std::pair<int, Pose>> Mapper::mapTrajectory() const {
  std::vector<std::pair<int, Pose>> out;
  size_t k = 0;  // the newest keyframe at or before the frame
  for (const auto& [frame, tp] : frames_) {
    while (k + 1 < keyframes_.size() && keyframes_[k + 1].frame <= frame) ++k;
    Pose correction = map_from_world_;
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
