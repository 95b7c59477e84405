#include "lidar_odometry.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "dlslot/box_filter.hpp"
#include "dlslot/cpu_clock.hpp"
#include "fallback_motion.hpp"
#include "rigid_motion.hpp"
#include "scan_to_map.hpp"

namespace dlslot::odometry {

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

double angleOf(const Pose& T) { return Eigen::AngleAxisd(T.linear()).angle(); }

// Covariance of the fallback prediction: the configured sigmas.
Matrix6d fallbackCovariance(const OdometryConfig& cfg) {
  const double st = cfg.fallback_sigma_m, sr = cfg.fallback_sigma_deg * M_PI / 180.0;
  Vector6d var;
  var << st * st, st * st, st * st, sr * sr, sr * sr, sr * sr;
  return var.asDiagonal();
}

// Covariance of the refined pose: the scan-to-map information H / sigma^2 plus the fallback's
// information, so that a degenerate direction is never more certain than the prediction.
Matrix6d solveCovariance(const Matrix6d& normal_matrix, const OdometryConfig& cfg) {
  const double s2 = cfg.residual_sigma_m * cfg.residual_sigma_m;
  const Matrix6d info = normal_matrix / s2 + fallbackCovariance(cfg).inverse();
  return info.inverse();
}

}  // namespace

LidarOdometry::LidarOdometry(OdometryConfig cfg)
    : cfg_(std::move(cfg)),
      map_(cfg_.scan_to_map) {}

void LidarOdometry::reset() {
  map_.clear();
  reference_ = ScanReference();
  T_world_reference_ = T_world_last_ = velocity_ = Pose::Identity();
  started_ = moving_ = false;
  fallbacks_ = 0;
  registered_velocity_ = Pose::Identity();
  last_index_ = 0;
}

void LidarOdometry::fallBack(Status status, const std::string& why, const Pose& prediction, OdometryResult& out) {
  out.status = status;
  out.status_text = why;
  out.T_world_lidar = prediction;
  out.delta = T_world_last_.inverse() * prediction;
  out.covariance = fallbackCovariance(cfg_);
  T_world_last_ = prediction;
  velocity_ = fallbackVelocity(velocity_, ++fallbacks_);
}

OdometryResult LidarOdometry::process(const Frame& frame, bool detections_available) {
  const auto t_total = Clock::now();
  OdometryResult out;
  out.frame = frame.index;
  out.num_points_in = static_cast<int>(frame.scan.cols());
  out.detections_used = cfg_.remove_detected_objects && detections_available;
  // Published stage times are wall ms; the detail is CPU ms of this thread (the same on a busy
  // machine as on an idle one).
  double s2s_ms = 0.0, s2m_ms = 0.0;
  auto finish = [&]() -> OdometryResult {
    out.timings.emplace_back("scan_to_scan", s2s_ms);
    out.timings.emplace_back("scan_to_map", s2m_ms);
    out.timings.emplace_back("total", msSince(t_total));
    return out;
  };

  // Features, after removing the points of potential dynamic objects (A-LOAM*, paper III-D), but
  // not the ground they stand on (box_filter.hpp, removalVolume).
  auto t = Clock::now();
  double cpu = threadCpuMs();
  std::vector<bool> inside;
  if (out.detections_used && !frame.detections.empty()) {
    inside = objectPoints(frame.scan, frame.detections, cfg_.box_margin_m, cfg_.ground_clearance_m);
    for (bool in : inside) out.num_points_removed += in ? 1 : 0;
  }
  out.detail.emplace_back("box_removal", threadCpuMs() - cpu);
  cpu = threadCpuMs();
  ScanFeatures features = extractFeatures(frame.scan, cfg_.features, inside.empty() ? nullptr : &inside);
  out.detail.emplace_back("feature_extraction", threadCpuMs() - cpu);
  out.num_edge = static_cast<int>(features.sharp.size());
  out.num_plane = static_cast<int>(features.flat.size());
  out.timings.emplace_back("features", msSince(t));

  // Frames lost on the way (a gap in the indices) moved the vehicle too.
  const int frames = started_ ? std::max(1, frame.index - last_index_) : 1;
  last_index_ = frame.index;
  const Pose prediction = T_world_last_ * orthonormalized(steps(velocity_, frames));
  if (features.num_points < cfg_.min_points || static_cast<int>(features.less_sharp.size()) < cfg_.min_edge_features ||
      static_cast<int>(features.less_flat.size()) < cfg_.min_plane_features) {
    fallBack(Status::FallbackFewPoints,
             "too few points or features (" + std::to_string(features.num_points) + " points, " +
                 std::to_string(features.less_sharp.size()) + " edges, " + std::to_string(features.less_flat.size()) +
                 " planes)",
             prediction, out);
    return finish();
  }

  // Scan-to-scan from the prediction (the previous scan's edges and planes); false when it fails.
  double s2s_index = 0.0, s2s_match = 0.0, s2s_solve = 0.0, s2m_match = 0.0, s2m_solve = 0.0;
  Pose s2s_pose = prediction;
  auto scanToScan = [&]() -> bool {
    const auto t_s2s = Clock::now();
    const double cpu_index = threadCpuMs();
    reference_.index();
    s2s_index += threadCpuMs() - cpu_index;
    Registration s2s =
        moving_ ? registerScanToScan(features, reference_, T_world_reference_.inverse() * prediction, cfg_.scan_to_scan)
                : registerFirstMotion(features, reference_, cfg_.scan_to_scan);
    s2s_match += s2s.match_ms;
    s2s_solve += s2s.solve_ms;
    // Back from fallbacks the prediction rests (fallback_motion.hpp) but the vehicle may have kept
    // its speed: scan-to-scan from there too, and the solution explaining more of the scan wins.
    if (fallbacks_ > 0 && moving_) {
      const Registration kept = registerScanToScan(features, reference_, steps(registered_velocity_, fallbacks_ + 1),
                                                   cfg_.scan_to_scan);
      s2s_match += kept.match_ms;
      s2s_solve += kept.solve_ms;
      if (kept.solution.ok && (!s2s.solution.ok || kept.solution.num_inliers > s2s.solution.num_inliers)) s2s = kept;
    }
    s2s_ms += msSince(t_s2s);
    if (!s2s.solution.ok) {
      fallBack(Status::FallbackSolveFailed,
               "scan-to-scan failed (" + std::to_string(s2s.num_correspondences) + " correspondences)", prediction,
               out);
      return false;
    }
    s2s_pose = T_world_reference_ * s2s.solution.T_ref_cur;
    return true;
  };
  auto addDetail = [&] {
    out.detail.emplace_back("s2s_index", s2s_index);
    out.detail.emplace_back("s2s_match", s2s_match);
    out.detail.emplace_back("s2s_solve", s2s_solve);
    out.detail.emplace_back("s2m_match", s2m_match);
    out.detail.emplace_back("s2m_solve", s2m_solve);
  };
  // Scan-to-scan first as in A-LOAM when configured, and where the prediction is weak: no
  // velocity yet, frames lost since the last scan, or fallbacks (then the map registration is
  // checked against it, below).
  const bool scan_to_scan_first =
      started_ && (cfg_.scan_to_scan.every_scan || !moving_ || frames > 1 || fallbacks_ > 0);
  if (scan_to_scan_first && !scanToScan()) {
    addDetail();
    return finish();
  }

  // Scan-to-map: refine against the local map, then add this scan to it.
  t = Clock::now();
  cpu = threadCpuMs();
  const FeatureCloud edges = downsample(features.less_sharp, cfg_.scan_to_map.edge_voxel_m);
  const FeatureCloud planes = downsample(features.less_flat, cfg_.scan_to_map.plane_voxel_m);
  out.detail.emplace_back("s2m_downsample", threadCpuMs() - cpu);
  out.num_map_edge = static_cast<int>(map_.edges().size());
  out.num_map_plane = static_cast<int>(map_.planes().size());
  // Why a map registration is not taken ("" when it is).
  // After fallbacks the prediction is a guess: a solution far from it is taken when scan-to-map
  // agrees with scan-to-scan (re-anchoring); otherwise one bad solution is kept out.
  auto beyond = [&](const Pose& c) {
    return c.translation().norm() > cfg_.max_correction_m || angleOf(c) > cfg_.max_correction_deg * M_PI / 180.0;
  };
  auto failureOf = [&](const Registration& s2m) -> std::string {
    const Pose correction = prediction.inverse() * s2m.solution.T_ref_cur;
    if (!s2m.solution.ok)
      return "scan-to-map failed (" + std::to_string(s2m.num_correspondences) + " correspondences)";
    const bool anchored = fallbacks_ > 0 && !beyond(s2s_pose.inverse() * s2m.solution.T_ref_cur);
    if (moving_ && beyond(correction) && !anchored)
      return "solution jumped " + std::to_string(correction.translation().norm()) + " m from the prediction";
    return "";
  };
  auto scanToMap = [&](const Pose& guess) {
    const Registration s2m = registerScanToMap(edges, planes, map_, guess, cfg_.scan_to_map);
    s2m_match += s2m.match_ms;
    s2m_solve += s2m.solve_ms;
    return s2m;
  };
  Pose pose = Pose::Identity();
  if (started_) {
    Registration s2m = scanToMap(scan_to_scan_first ? s2s_pose : prediction);
    // Started from the prediction and failed or jumped: scan-to-scan, whose wider search
    // (max_match_distance_m) reaches farther from a poor prediction, gives it a second start.
    if (!scan_to_scan_first && !failureOf(s2m).empty()) {
      s2m_ms += msSince(t);
      const bool ok = scanToScan();
      t = Clock::now();
      if (!ok) {
        addDetail();
        return finish();
      }
      s2m = scanToMap(s2s_pose);
    }
    const std::string failure = failureOf(s2m);
    if (!failure.empty()) {
      s2m_ms += msSince(t);
      addDetail();
      fallBack(Status::FallbackSolveFailed, failure, prediction, out);
      return finish();
    }
    pose = s2m.solution.T_ref_cur;
    out.status = Status::Ok;
    if (fallbacks_ > 0) {  // registered again: said once, for the logs
      const Pose correction = prediction.inverse() * pose;
      out.status_text = std::string(moving_ && beyond(correction) ? "re-anchored" : "registered again") + " after " +
                        std::to_string(fallbacks_) + " fallback frames, " +
                        std::to_string(correction.translation().norm()) + " m from the prediction";
    }
    out.min_eigenvalue = s2m.solution.min_eigenvalue;
    out.residual_mean = s2m.solution.residual_mean;
    out.num_correspondences = s2m.num_correspondences;
    out.covariance = solveCovariance(s2m.solution.normal_matrix, cfg_);
  } else {
    out.status = Status::FirstFrame;
    out.covariance = Matrix6d::Zero();
    pose = T_world_last_;
  }
  addDetail();
  cpu = threadCpuMs();
  map_.insert(edges, planes, pose);
  out.detail.emplace_back("map_update", threadCpuMs() - cpu);
  s2m_ms += msSince(t);

  out.T_world_lidar = pose;
  out.delta = T_world_last_.inverse() * pose;
  if (started_) {
    // After fallbacks the last published pose was a guess: the velocity is the mean motion since
    // the last registered scan instead.
    velocity_ = registered_velocity_ = fallbacks_ > 0
                                           ? scaledMotion(T_world_reference_.inverse() * pose, 1.0 / (fallbacks_ + 1))
                                           : frames > 1 ? scaledMotion(out.delta, 1.0 / frames) : out.delta;
    moving_ = true;
  }
  fallbacks_ = 0;
  T_world_last_ = T_world_reference_ = pose;
  cpu = threadCpuMs();
  reference_.reset(std::move(features));  // indexed only when a later scan needs scan-to-scan
  out.detail.emplace_back("s2s_reference", threadCpuMs() - cpu);
  started_ = true;
  return finish();
}

}  // namespace dlslot::odometry
