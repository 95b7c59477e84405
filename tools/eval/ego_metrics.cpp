#include "ego_metrics.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

namespace dlslot::eval {

const std::vector<double> kDevkitLengths = {100, 200, 300, 400, 500, 600, 700, 800};
const std::vector<double> kShortLengths = {10, 20, 30, 40, 50, 60, 70, 80};

namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

void requireSameFrames(const Trajectory& est, const Trajectory& gt) {
  if (est.frames != gt.frames)
    throw std::invalid_argument("estimated and ground-truth trajectories cover different frames (" +
                                std::to_string(est.size()) + " vs " + std::to_string(gt.size()) + " poses)");
}

// Rotation angle of R. The devkit's acos(0.5 (trace - 1)) in a form that stays accurate for the
// tiny angles of good estimates (acos near 1 loses half the digits).
double rotationAngle(const Eigen::Matrix3d& R) {
  const Eigen::Vector3d axis_sin(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1));  // 2 sin(angle) axis
  return std::atan2(0.5 * axis_sin.norm(), 0.5 * (R.trace() - 1.0));
}

std::vector<Eigen::Vector3d> positions(const Trajectory& t) {
  std::vector<Eigen::Vector3d> p;
  p.reserve(t.size());
  for (const Pose& T : t.poses) p.push_back(T.translation());
  return p;
}

}  // namespace

Pose alignUmeyama(const std::vector<Eigen::Vector3d>& estimated, const std::vector<Eigen::Vector3d>& truth) {
  if (estimated.size() != truth.size() || estimated.empty())
    throw std::invalid_argument("alignment needs equally many points, at least one");
  const Eigen::Index n = static_cast<Eigen::Index>(estimated.size());
  Eigen::Matrix3Xd src(3, n), dst(3, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    src.col(i) = estimated[i];
    dst.col(i) = truth[i];
  }
  Pose T = Pose::Identity();
  if (n == 1) {
    T.translation() = dst.col(0) - src.col(0);
    return T;
  }
  T.matrix() = Eigen::umeyama(src, dst, false);
  return T;
}

std::vector<double> alignedPositionErrors(const Trajectory& est, const Trajectory& gt) {
  requireSameFrames(est, gt);
  if (est.empty()) return {};
  const Pose A = alignUmeyama(positions(est), positions(gt));
  std::vector<double> e(est.size());
  for (size_t i = 0; i < est.size(); ++i) e[i] = (A * est.poses[i].translation() - gt.poses[i].translation()).norm();
  return e;
}

double ateRmse(const Trajectory& est, const Trajectory& gt, bool align) {
  requireSameFrames(est, gt);
  if (est.empty()) throw std::invalid_argument("ATE of an empty trajectory");
  double sum = 0.0;
  if (align) {
    for (double e : alignedPositionErrors(est, gt)) sum += e * e;
  } else {
    for (size_t i = 0; i < est.size(); ++i)
      sum += (est.poses[i].translation() - gt.poses[i].translation()).squaredNorm();
  }
  return std::sqrt(sum / est.size());
}

std::vector<double> pathDistances(const Trajectory& gt) {
  std::vector<double> d(gt.size(), 0.0);
  for (size_t i = 1; i < gt.size(); ++i)
    d[i] = d[i - 1] + (gt.poses[i].translation() - gt.poses[i - 1].translation()).norm();
  return d;
}

std::optional<Rpe> relativePoseError(const Trajectory& est, const Trajectory& gt, int delta) {
  requireSameFrames(est, gt);
  std::map<int, size_t> index;
  for (size_t i = 0; i < gt.size(); ++i) index[gt.frames[i]] = i;
  double sum_t = 0, sum_r = 0, sum_v = 0;
  int pairs = 0, timed = 0;
  for (size_t i = 0; i < gt.size(); ++i) {
    const auto it = index.find(gt.frames[i] + delta);
    if (it == index.end()) continue;
    const size_t j = it->second;
    const Pose rel_gt = gt.poses[i].inverse() * gt.poses[j];
    const Pose rel_est = est.poses[i].inverse() * est.poses[j];
    const Pose E = rel_gt.inverse() * rel_est;
    sum_t += E.translation().squaredNorm();
    const double r = rotationAngle(E.linear()) * kRadToDeg;
    sum_r += r * r;
    ++pairs;
    const double dt = gt.stamps.size() == gt.size() ? gt.stamps[j] - gt.stamps[i] : 0.0;
    if (dt > 0) {
      sum_v += E.translation().squaredNorm() / (dt * dt);
      ++timed;
    }
  }
  if (pairs == 0) return std::nullopt;
  Rpe rpe{std::sqrt(sum_t / pairs), std::sqrt(sum_r / pairs), pairs, std::nullopt};
  if (timed > 0) rpe.velocity_rmse_mps = std::sqrt(sum_v / timed);
  return rpe;
}

std::optional<SegmentErrors> segmentErrors(const Trajectory& est, const Trajectory& gt,
                                           const std::vector<double>& lengths_m, int step_frames) {
  requireSameFrames(est, gt);
  const std::vector<double> dist = pathDistances(gt);
  const size_t n = gt.size();
  double sum_t = 0, sum_r = 0;
  int count = 0;
  std::map<double, std::pair<double, int>> by_length;  // length -> (sum of t_err/len, count)
  for (size_t first = 0; first < n; first += step_frames) {
    for (double len : lengths_m) {
      size_t last = first;
      while (last < n && !(dist[last] > dist[first] + len)) ++last;
      if (last == n) continue;  // the sequence ends before the segment does
      const Pose delta_gt = gt.poses[first].inverse() * gt.poses[last];
      const Pose delta_est = est.poses[first].inverse() * est.poses[last];
      const Pose error = delta_est.inverse() * delta_gt;
      const double t_err = error.translation().norm() / len;
      sum_t += t_err;
      sum_r += rotationAngle(error.linear()) / len;
      ++count;
      by_length[len].first += t_err;
      by_length[len].second += 1;
    }
  }
  if (count == 0) return std::nullopt;
  SegmentErrors s;
  s.t_rel_pct = 100.0 * sum_t / count;
  s.r_rel_deg_per_100m = 100.0 * kRadToDeg * sum_r / count;
  s.segments = count;
  for (const auto& [len, acc] : by_length) {
    s.lengths.push_back(len);
    s.t_rel_pct_by_length.push_back(100.0 * acc.first / acc.second);
  }
  return s;
}

std::optional<double> implausibleSpeedJumps(const Trajectory& est) {
  if (est.stamps.size() != est.size() || est.size() < 3) return std::nullopt;
  constexpr double kMaxAcceleration = 2.0 * 9.81;  // m/s^2
  int jumps = 0;
  double last_speed = -1.0;
  for (size_t i = 1; i < est.size(); ++i) {
    const double dt = est.stamps[i] - est.stamps[i - 1];
    if (!(dt > 0)) {
      last_speed = -1.0;
      continue;
    }
    const double speed = (est.poses[i].translation() - est.poses[i - 1].translation()).norm() / dt;
    if (last_speed >= 0 && std::abs(speed - last_speed) > kMaxAcceleration * dt) ++jumps;
    last_speed = speed;
  }
  return jumps;
}

EgoMetrics evaluateEgo(const Trajectory& est, const Trajectory& gt) {
  requireSameFrames(est, gt);
  EgoMetrics m;
  m.frames = static_cast<int>(est.size());
  if (est.empty()) return m;
  m.path_length_m = pathDistances(gt).back();
  m.implausible_frames = implausibleSpeedJumps(est);
  m.ate_rmse_m = ateRmse(est, gt, true);
  m.ate_unaligned_rmse_m = ateRmse(est, gt, false);
  if (const auto r = relativePoseError(est, gt, 1)) {
    m.rpe1_t_m = r->t_rmse_m;
    m.rpe1_r_deg = r->r_rmse_deg;
  }
  if (const auto r = relativePoseError(est, gt, 10)) {
    m.rpe10_t_m = r->t_rmse_m;
    m.rpe10_r_deg = r->r_rmse_deg;
  }
  if (const auto r = relativePoseError(est, gt, 5)) m.velocity_rmse_mps = r->velocity_rmse_mps;
  m.devkit = segmentErrors(est, gt, kDevkitLengths);
  if (m.devkit) {
    m.t_rel_pct = m.devkit->t_rel_pct;
    m.r_rel_deg_per_100m = m.devkit->r_rel_deg_per_100m;
  }
  m.short_segments = segmentErrors(est, gt, kShortLengths);
  if (m.short_segments) {
    m.t_rel_short_pct = m.short_segments->t_rel_pct;
    m.r_rel_short_deg_per_100m = m.short_segments->r_rel_deg_per_100m;
  }
  return m;
}

}  // namespace dlslot::eval
