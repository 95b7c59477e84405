#include "lidar_odometry.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "dlslot/box_filter.hpp"
#include "dlslot/cpu_clock.hpp"
#include "degeneracy.hpp"
#include "fallback_motion.hpp"
#include "feature_deskew.hpp"
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

// Covariance of a registration's translation (rotation marginalised), the prediction's
// information added as in solveCovariance.
Eigen::Matrix3d translationCovariance(const TranslationConstraint& c, const OdometryConfig& cfg) {
  const double s2 = cfg.residual_sigma_m * cfg.residual_sigma_m;
  const double prior = 1.0 / (cfg.fallback_sigma_m * cfg.fallback_sigma_m);
  Eigen::Vector3d var;
  for (int i = 0; i < 3; ++i) var(i) = 1.0 / (c.information(i) / s2 + prior);
  return c.directions * var.asDiagonal() * c.directions.transpose();
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
  frames_since_check_ = 0;
  pending_disagreement_m_ = 0.0;
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
  // Put back on their rays (in the sensor's frame at firing time, so before the de-skew), then
  // moved to the scan's reference instant with the vehicle's motion of the previous frame
  // (feature_deskew.hpp); the first scans, before any motion is known, stay as they are.
  cpu = threadCpuMs();
  correctElevation(features, cfg_.vertical_angle_error_rad);
  if (moving_) deskewFeatures(features, cfg_.sweep, vehicleTwist(velocity_, cfg_.sweep.period_s));
  out.detail.emplace_back("deskew", threadCpuMs() - cpu);
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
  Registration s2s_last;  // the last scan-to-scan registration of this frame
  // fall_back: a failure publishes the prediction (false: only reported, the caller goes on).
  auto scanToScan = [&](bool fall_back = true) -> bool {
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
    s2s_last = s2s;
    if (!s2s.solution.ok) {
      if (!fall_back) return false;
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
  bool reanchored = false;  // a weak direction's check disagreed: scan-to-scan's pose wins
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
    const bool anchored =
        (fallbacks_ > 0 || reanchored) && !beyond(s2s_pose.inverse() * s2m.solution.T_ref_cur);
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
    } else if (!scan_to_scan_first && moving_) {
      // The map registration started from the constant-velocity prediction. Along a direction
      // it hardly constrains (a highway: the position along the road) its solution is that
      // prediction, and a map built with a wrong velocity agrees with it (every scan was put in
      // where the wrong velocity said): a wrong velocity would be kept for ever. Scan-to-scan
      // depends on neither the map nor the velocity's history, and its wider search reaches
      // farther from a poor prediction. It checks the map registration where a direction is weak
      // (degeneracy.hpp), and every check_every_frames frames whatever the constraint (a bound on
      // how long a wrong velocity lasts, at a fraction of a scan-to-scan per frame). Where the
      // two disagree beyond both covariances (chi-square, 1 degree of freedom) and by more than
      // the map registration's own search can pull back, scan-to-scan's motion is taken and the
      // map, built with the wrong velocity, is started over.
      //
      // Scan-to-scan from the prediction alone is not independent of the velocity: its
      // correspondences stick to surfaces that run along the motion (rails, road, walls), and from
      // a prediction 2 m off it moves only 0.1-0.15 m and stops after its outer_iterations
      // searches without converging. So when it did not converge, or disagrees, the velocity is
      // suspect and scan-to-scan starts again from forward motion hypotheses that do not depend
      // on it (registerMotionHypotheses: 0 .. max_forward_m, each within one registration's reach
      // of the next); the one explaining most of the scan is the independent estimate.
      const TranslationConstraint map_c = translationConstraint(s2m.solution.normal_matrix);
      const bool weak = map_c.ratio() < cfg_.weak_direction_ratio;
      const double pending = pending_disagreement_m_;  // the last scan's check disagreed by this
      pending_disagreement_m_ = 0.0;
      const bool audit =
          (cfg_.check_every_frames > 0 && frames_since_check_ + 1 >= cfg_.check_every_frames) || pending != 0.0;
      if (weak || audit) {
        frames_since_check_ = -1;  // counted up to 0 below
        out.velocity_checked = true;
        if (weak) {
          out.weak_direction = map_c.weakest();
          out.degeneracy = Degeneracy::Unchecked;
        }
        s2m_ms += msSince(t);
        const Pose& map_pose = s2m.solution.T_ref_cur;
        // The check against the map registration: true when scan-to-scan can tell (it is not as
        // weak along the direction compared), filling out.check_*; `disagrees` when it does
        // beyond both covariances and beyond what the map's own search pulls back.
        bool disagrees = false;
        auto compare = [&]() -> bool {
          out.check_disagreement_m = out.check_chi2 = 0.0;
          disagrees = false;
          const TranslationConstraint s2s_c = translationConstraint(s2s_last.solution.normal_matrix);
          const Eigen::Vector3d d = map_pose.linear().transpose() * (s2s_pose.translation() - map_pose.translation());
          // The weak direction, or on an audit the direction of the disagreement itself.
          const Eigen::Vector3d v = weak || d.norm() < 1e-9 ? map_c.weakest() : Eigen::Vector3d(d.normalized());
          // Scan-to-scan as weak along v (the same missing structure) cannot tell.
          const double s2s_info =
              v.dot(s2s_c.directions * s2s_c.information.asDiagonal() * s2s_c.directions.transpose() * v);
          if (s2s_info < cfg_.weak_direction_ratio * s2s_c.information(2)) return false;
          out.check_disagreement_m = v.dot(d);
          out.check_chi2 = chiSquareAlong(d, v, translationCovariance(map_c, cfg_), translationCovariance(s2s_c, cfg_));
          out.check_direction = v;
          disagrees = out.check_chi2 > cfg_.check_chi2 && std::abs(out.check_disagreement_m) > cfg_.check_min_disagreement_m;
          return true;
        };
        bool ok = scanToScan(false) && compare();
        // The correspondences it left unexplained may agree on another forward motion (traffic
        // moving with the ego can hold scan-to-scan at the wrong velocity while the static
        // structure says otherwise): scan-to-scan from there too, the one explaining more wins.
        if (ok && !disagrees) {
          const auto t_s2s = Clock::now();
          const double cpu_match = threadCpuMs();
          const Pose T = s2s_last.solution.T_ref_cur;
          const Matches m = matchScanToScan(features, reference_, T, cfg_.scan_to_scan);
          s2s_match += threadCpuMs() - cpu_match;
          const double shift = outlierShift(m, T, T.linear().col(0), cfg_.scan_to_scan.solver.huber_delta_m,
                                            cfg_.scan_to_scan.hypothesis_spacing_m, cfg_.scan_to_scan.max_forward_m,
                                            cfg_.scan_to_scan.min_correspondences);
          if (std::isfinite(shift)) {
            Pose start = T;
            start.translation() += shift * T.linear().col(0);
            const Registration other = registerScanToScan(features, reference_, start, cfg_.scan_to_scan);
            s2s_match += other.match_ms;
            s2s_solve += other.solve_ms;
            out.motion_hypotheses = 1;
            if (other.solution.ok && other.solution.num_inliers > s2s_last.solution.num_inliers) {
              s2s_last = other;
              s2s_pose = T_world_reference_ * other.solution.T_ref_cur;
              ok = compare();
            }
          }
          s2s_ms += msSince(t_s2s);
        }
        // Still moving by more than its convergence step: the start was beyond its reach.
        if (!ok || disagrees || s2s_last.last_step_m >= cfg_.scan_to_scan.solver.converged_step_m) {
          const auto t_s2s = Clock::now();
          Registration searched = registerMotionHypotheses(features, reference_, T_world_reference_.inverse() * prediction,
                                                           forwardHypotheses(cfg_.scan_to_scan), cfg_.scan_to_scan,
                                                           &out.motion_hypotheses);
          s2s_match += searched.match_ms;
          s2s_solve += searched.solve_ms;
          s2s_ms += msSince(t_s2s);
          if (searched.solution.ok) {
            s2s_last = searched;
            s2s_pose = T_world_reference_ * searched.solution.T_ref_cur;
            ok = compare();
          }
        }
        t = Clock::now();
        if (ok) {
          if (weak) out.degeneracy = Degeneracy::Confirmed;
          // One scan pair can be outvoted by chance (along a highway the inlier counts of motions
          // metres apart differ by a few percent); a wrong velocity disagrees again on the next
          // scan, the same way, a chance winner does not. So a first disagreement only makes the
          // next scan checked too, and the second in a row re-anchors.
          if (disagrees && pending * out.check_disagreement_m > 0.0) {
            reanchored = true;
            out.weak_direction = out.check_direction;
            out.degeneracy = Degeneracy::Reanchored;
          } else if (disagrees) {
            pending_disagreement_m_ = out.check_disagreement_m;
            out.weak_direction = out.check_direction;
            out.degeneracy = Degeneracy::Suspected;
          }
        }
      }
    }
    const std::string failure = reanchored ? "" : failureOf(s2m);
    if (!failure.empty()) {
      s2m_ms += msSince(t);
      addDetail();
      fallBack(Status::FallbackSolveFailed, failure, prediction, out);
      return finish();
    }
    // Re-anchored: this scan's motion is scan-to-scan's, the map starts over from this scan.
    const Registration& used = reanchored ? s2s_last : s2m;
    pose = reanchored ? s2s_pose : s2m.solution.T_ref_cur;
    if (reanchored) map_.clear();
    ++frames_since_check_;
    // The first motion won a vote of inlier counts, which along a highway can go to a chance
    // winner: the next map registration, the first from a velocity, is checked.
    if (!moving_) frames_since_check_ = std::max(0, cfg_.check_every_frames - 1);
    out.status = Status::Ok;
    if (fallbacks_ > 0) {  // registered again: said once, for the logs
      const Pose correction = prediction.inverse() * pose;
      out.status_text = std::string(moving_ && beyond(correction) ? "re-anchored" : "registered again") + " after " +
                        std::to_string(fallbacks_) + " fallback frames, " +
                        std::to_string(correction.translation().norm()) + " m from the prediction";
    }
    {
      const TranslationConstraint c = translationConstraint(used.solution.normal_matrix);
      out.translation_information = c.information;
      if (out.degeneracy == Degeneracy::None) out.weak_direction = c.weakest();
      if (out.degeneracy != Degeneracy::None) {
        char buf[300];
        const Eigen::Vector3d& v = out.weak_direction;
        const TranslationConstraint map_c = translationConstraint(s2m.solution.normal_matrix);
        // Why the velocity was checked: a weak direction of the map registration, or the
        // periodic check (a map built with a wrong velocity agrees with it).
        const bool was_weak = map_c.ratio() < cfg_.weak_direction_ratio;
        const std::string why =
            was_weak ? "weakly constrained along (" : "velocity check (every " + std::to_string(cfg_.check_every_frames) +
                                                          " frames) along (";
        std::snprintf(buf, sizeof buf, "%s%.2f, %.2f, %.2f) (information ratio %.1e%s): %s", why.c_str(), v.x(), v.y(),
                      v.z(), map_c.ratio(),
                      out.motion_hypotheses > 0
                          ? (", " + std::to_string(out.motion_hypotheses) + " motion hypotheses searched").c_str()
                          : "",
                      out.degeneracy == Degeneracy::Unchecked   ? "scan-to-scan could not check it"
                      : out.degeneracy == Degeneracy::Confirmed ? "scan-to-scan agrees"
                      : out.degeneracy == Degeneracy::Suspected
                          ? "scan-to-scan disagreed, the next scan is checked too"
                          : "scan-to-scan disagreed twice in a row, velocity re-anchored, map restarted");
        std::string text = buf;
        if (out.degeneracy == Degeneracy::Reanchored || out.degeneracy == Degeneracy::Suspected)
          text += " (" + std::to_string(out.check_disagreement_m) + " m, chi-square " + std::to_string(out.check_chi2) + ")";
        out.status_text += (out.status_text.empty() ? "" : "; ") + text;
      }
    }
    out.min_eigenvalue = used.solution.min_eigenvalue;
    out.residual_mean = used.solution.residual_mean;
    out.num_correspondences = used.num_correspondences;
    out.covariance = solveCovariance(used.solution.normal_matrix, cfg_);
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
    if (!moving_ && cfg_.sweep.period_s > 0) {
      // The first motion known: the scans before it went into the local map as fired, sheared
      // (5-9 cm of error three scans later on a 10 m/s street). The map starts again from this
      // scan, de-skewed with it; the pose already found stays.
      deskewFeatures(features, cfg_.sweep, vehicleTwist(velocity_, cfg_.sweep.period_s));
      map_.clear();
      map_.insert(downsample(features.less_sharp, cfg_.scan_to_map.edge_voxel_m),
                  downsample(features.less_flat, cfg_.scan_to_map.plane_voxel_m), pose);
    }
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
