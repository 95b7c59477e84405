#include "backend/object_registration.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace dlslot::backend {
namespace {

std::vector<Eigen::Vector3d> thin(const ObjectPoints& points, double cell, int max_points) {
  std::vector<Eigen::Vector3d> out;
  const std::vector<int> kept = thinIndices(points, cell, max_points);
  out.reserve(kept.size());
  for (int i : kept) out.push_back(points[static_cast<size_t>(i)].cast<double>());
  return out;
}

}  // namespace

// Cells, not a stride over the scan: a scan lists its points ring by ring, and every k-th point
// of that order leaves lines, not surfaces.
std::vector<int> thinIndices(const ObjectPoints& points, double cell, int max_points) {
  std::vector<int> out;
  if (points.empty()) return out;
  Eigen::Vector3d lo = points.front().cast<double>(), hi = lo;
  for (const Eigen::Vector3f& p : points) {
    lo = lo.cwiseMin(p.cast<double>());
    hi = hi.cwiseMax(p.cast<double>());
  }
  long dims[3];
  for (;;) {
    for (int k = 0; k < 3; ++k) dims[k] = static_cast<long>((hi[k] - lo[k]) / cell) + 1;
    if (dims[0] * dims[1] * dims[2] <= 400'000) break;
    cell *= 1.5;
  }
  std::vector<char> taken(static_cast<size_t>(dims[0] * dims[1] * dims[2]), 0);
  out.reserve(points.size());
  const double inv_cell = 1.0 / cell;
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d q = points[i].cast<double>();
    long c[3];
    bool inside = true;
    for (int k = 0; k < 3; ++k) {
      const double f = (q[k] - lo[k]) * inv_cell;
      inside &= f >= 0 && f < dims[k];
      c[k] = inside ? static_cast<long>(f) : 0;
    }
    if (!inside) continue;
    char& t = taken[static_cast<size_t>((c[2] * dims[1] + c[1]) * dims[0] + c[0])];
    if (t) continue;
    t = 1;
    out.push_back(static_cast<int>(i));
  }
  if (static_cast<int>(out.size()) > max_points) {
    const double step = static_cast<double>(out.size()) / max_points;
    std::vector<int> kept;
    kept.reserve(max_points);
    for (int i = 0; i < max_points; ++i) kept.push_back(out[static_cast<size_t>(i * step)]);
    out.swap(kept);
  }
  return out;
}

const char* toString(RegistrationOutcome outcome) {
  switch (outcome) {
    case RegistrationOutcome::kMeasured: return "measured";
    case RegistrationOutcome::kPartial: return "partial";
    case RegistrationOutcome::kTooFewPoints: return "too_few_points";
    case RegistrationOutcome::kDegenerate: return "degenerate";
    case RegistrationOutcome::kPoorFit: return "poor_fit";
    case RegistrationOutcome::kDiverged: return "diverged";
  }
  return "?";
}

PreparedObject::PreparedObject(const ObjectPoints& points, double range, const RegistrationOptions& o, bool with_planes)
    : raw_points_(static_cast<int>(points.size())) {
  voxel_ = std::max(o.min_voxel, o.voxel_per_m * range);
  if (points.empty()) return;
  // A near car has thousands of points: thinned to one point per half voxel (and a bounded
  // number), which bounds the work per object.
  points_ = thin(points, 0.5 * voxel_, o.max_target_points);
  for (const Eigen::Vector3d& p : points_) centroid_ += p;
  centroid_ /= static_cast<double>(points_.size());
  Eigen::Vector3d lo = points_.front(), hi = points_.front();
  for (const Eigen::Vector3d& p : points_) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  // A long truck at a small voxel: grow the voxel until the grid stays small.
  const int pad = 2;
  for (;;) {
    origin_ = lo - Eigen::Vector3d::Constant(pad * voxel_);
    for (int k = 0; k < 3; ++k) dims_[k] = static_cast<int>(std::floor((hi[k] - lo[k]) / voxel_)) + 1 + 2 * pad;
    if (static_cast<long>(dims_[0]) * dims_[1] * dims_[2] <= 200'000) break;
    voxel_ *= 1.5;
  }
  const size_t n = static_cast<size_t>(dims_[0]) * dims_[1] * dims_[2];
  start_.assign(n + 1, 0);
  std::vector<long> cell(points_.size());
  for (size_t i = 0; i < points_.size(); ++i) {
    int c[3] = {0, 0, 0};
    cellOf(points_[i], c);  // inside: the grid spans the points
    cell[i] = (static_cast<long>(c[2]) * dims_[1] + c[1]) * dims_[0] + c[0];
    ++start_[cell[i] + 1];
  }
  for (size_t k = 1; k < start_.size(); ++k) start_[k] += start_[k - 1];
  members_.resize(points_.size());
  std::vector<int> next(start_.begin(), start_.end() - 1);
  for (size_t i = 0; i < points_.size(); ++i) members_[next[cell[i]]++] = static_cast<int>(i);
  // The source subsample: every k-th point (the thinned points are in scan order, cell by cell),
  // each with its plane.
  if (!with_planes) return;
  const size_t m = std::min(points_.size(), static_cast<size_t>(std::max(1, o.max_source_points)));
  const double step = static_cast<double>(points_.size()) / static_cast<double>(m);
  source_.reserve(m);
  planes_.reserve(m);
  for (size_t i = 0; i < m; ++i) {
    source_.push_back(points_[static_cast<size_t>(static_cast<double>(i) * step)]);
    planes_.push_back(fit(source_.back(), o));
  }
}

bool PreparedObject::cellOf(const Eigen::Vector3d& p, int* c) const {
  for (int k = 0; k < 3; ++k) {
    const double f = (p[k] - origin_[k]) / voxel_;
    if (!(f >= 0) || f >= dims_[k]) return false;
    c[k] = static_cast<int>(f);
  }
  return true;
}

int PreparedObject::nearest(const Eigen::Vector3d& q, double* d2) const {
  int best = -1;
  double best_d2 = 1e300;
  *d2 = best_d2;
  int c[3];
  if (!cellOf(q, c)) return best;
  // First the 2x2x2 voxels on q's side of its voxel: they hold every point within half a voxel
  // of q, so a point found there that near is the nearest of the 3x3x3 neighbourhood too (most
  // queries, once the iterations settle, at 8 voxels instead of 27).
  int lo[3], hi[3];
  for (int k = 0; k < 3; ++k) {
    const double f = (q[k] - origin_[k]) / voxel_ - c[k];
    lo[k] = std::max(0, f < 0.5 ? c[k] - 1 : c[k]);
    hi[k] = std::min(dims_[k] - 1, f < 0.5 ? c[k] : c[k] + 1);
  }
  auto scan = [&](const int* a, const int* b) {
    for (int z = a[2]; z <= b[2]; ++z)
      for (int y = a[1]; y <= b[1]; ++y) {
        const long row = (static_cast<long>(z) * dims_[1] + y) * dims_[0];
        for (int m = start_[row + a[0]]; m < start_[row + b[0] + 1]; ++m) {
          const double d = (points_[members_[m]] - q).squaredNorm();
          if (d < best_d2) {
            best_d2 = d;
            best = members_[m];
          }
        }
      }
  };
  scan(lo, hi);
  if (best_d2 > 0.25 * voxel_ * voxel_) {
    int a[3], b[3];
    for (int k = 0; k < 3; ++k) {
      a[k] = std::max(0, c[k] - 1);
      b[k] = std::min(dims_[k] - 1, c[k] + 1);
    }
    scan(a, b);  // the 2x2x2 again among the 27: cheaper than skipping them
  }
  *d2 = best_d2;
  return best;
}

PreparedObject::Plane PreparedObject::fit(const Eigen::Vector3d& p, const RegistrationOptions& o) const {
  int c[3];
  if (!cellOf(p, c)) return {};
  std::vector<std::pair<double, int>> near;
  near.reserve(64);
  for (int z = std::max(0, c[2] - 1); z <= std::min(dims_[2] - 1, c[2] + 1); ++z)
    for (int y = std::max(0, c[1] - 1); y <= std::min(dims_[1] - 1, c[1] + 1); ++y) {
      const long row = (static_cast<long>(z) * dims_[1] + y) * dims_[0];
      for (int m = start_[row + std::max(0, c[0] - 1)]; m < start_[row + std::min(dims_[0] - 1, c[0] + 1) + 1]; ++m)
        near.emplace_back((points_[members_[m]] - p).squaredNorm(), members_[m]);
    }
  const int k = std::min<int>(static_cast<int>(near.size()), o.plane_neighbours);
  if (k < o.min_plane_points) return {};
  std::nth_element(near.begin(), near.begin() + (k - 1), near.end());
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int i = 0; i < k; ++i) mean += points_[near[i].second];
  mean /= k;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (int i = 0; i < k; ++i) {
    const Eigen::Vector3d d = points_[near[i].second] - mean;
    cov += d * d.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es;
  es.computeDirect(cov / k);
  const Eigen::Vector3d ev = es.eigenvalues();  // ascending
  // A plane: one small eigenvalue, two spread ones (a single scan ring is a line: no plane).
  if (!(ev[1] > 1e-6) || ev[0] > o.max_planarity * ev[1]) return {};
  return Plane{true, es.eigenvectors().col(0)};
}

// Each measured direction v (an eigenvector of the centred information, translation and rotation
// parts v_t, v_r) gets the accuracy floor's variance a^2 = |v_t|^2 accuracy_m^2 + |v_r|^2
// accuracy_rad^2 added: lambda -> 1 / (1 / lambda + a^2). Unmeasured directions stay unmeasured.
Matrix6 withAccuracyFloor(const Matrix6& info, const RegistrationOptions& o) {
  Eigen::SelfAdjointEigenSolver<Matrix6> es(0.5 * (info + info.transpose()));
  const double lambda_max = std::max(es.eigenvalues().maxCoeff(), 0.0);
  Matrix6 out = Matrix6::Zero();
  for (int k = 0; k < 6; ++k) {
    const double lambda = es.eigenvalues()[k];
    if (!(lambda > 1e-12 * lambda_max)) continue;
    const Vector6 v = es.eigenvectors().col(k);
    const double a2 = v.head<3>().squaredNorm() * o.accuracy_m * o.accuracy_m +
                      v.tail<3>().squaredNorm() * o.accuracy_rad * o.accuracy_rad;
    out += v * v.transpose() * (lambda / (1.0 + lambda * a2));
  }
  return out;
}

RegistrationResult registerObject(const ObjectPoints& previous, const ObjectPoints& current, const Pose& prediction,
                                  double range, const RegistrationOptions& o) {
  if (static_cast<int>(previous.size()) < o.min_points || static_cast<int>(current.size()) < o.min_points) {
    RegistrationResult result;
    result.source_points = static_cast<int>(previous.size());
    result.target_points = static_cast<int>(current.size());
    result.motion = prediction;
    return result;  // kTooFewPoints
  }
  return registerObject(PreparedObject(previous, range, o), PreparedObject(current, range, o), prediction, o);
}

RegistrationResult inverted(const RegistrationResult& r) {
  RegistrationResult out = r;
  out.motion = r.motion.inverse();
  std::swap(out.source_points, out.target_points);
  // A perturbation d = (dt, dtheta) of M = (R, t) moves M^-1 by d' = J d: dtheta' = -R^T dtheta,
  // dt' = -R^T dt - R^T [t]x dtheta (first order). The same Mahalanobis length d^T I d = d'^T I' d'
  // gives I' = J^-T I J^-1.
  const Eigen::Matrix3d Rt = r.motion.linear().transpose();
  Matrix6 J = Matrix6::Zero();
  J.topLeftCorner<3, 3>() = -Rt;
  J.topRightCorner<3, 3>() = -Rt * skew(r.motion.translation());
  J.bottomRightCorner<3, 3>() = -Rt;
  const Matrix6 Jinv = J.inverse();
  out.information = Jinv.transpose() * r.information * Jinv;
  return out;
}

RegistrationResult registerToModel(const PreparedObject& model, const PreparedObject& current, const Pose& prediction,
                                   const RegistrationOptions& o) {
  return inverted(registerObject(current, model, prediction.inverse(), o));
}

RegistrationResult registerObject(const PreparedObject& previous, const PreparedObject& current, const Pose& prediction,
                                  const RegistrationOptions& o) {
  RegistrationResult result;
  result.source_points = previous.rawPoints();
  result.target_points = current.rawPoints();
  result.motion = prediction;
  if (previous.rawPoints() < o.min_points || current.rawPoints() < o.min_points) {
    result.outcome = RegistrationOutcome::kTooFewPoints;
    return result;
  }
  // Centred on the current points' centroid: rotations turn about the object, so translation and
  // rotation separate in the Hessian (about the world origin 30 m away they would not).
  const Eigen::Vector3d c = current.centroid();
  std::vector<Eigen::Vector3d> source = previous.sourcePoints();
  for (Eigen::Vector3d& p : source) p -= c;
  const std::vector<PreparedObject::Plane>& planes = previous.sourcePlanes();
  if (source.empty()) {
    result.outcome = RegistrationOutcome::kPoorFit;  // prepared without planes: not a source
    return result;
  }
  const std::vector<Eigen::Vector3d>& target = current.points();
  const double voxel = current.voxel();

  // M_c = T(-c) M T(c): q = R p + t in centred coordinates.
  Eigen::Matrix3d R = prediction.linear();
  Eigen::Vector3d t = prediction.linear() * c + prediction.translation() - c;
  const Eigen::Matrix3d R0 = R;
  const Eigen::Vector3d t0 = t;
  Matrix6 H = Matrix6::Zero();
  double sigma2 = o.point_sigma * o.point_sigma;
  int inliers = 0;
  double wr2 = 0, wsum = 0;
  // Each source point's correspondence and where the point was when it was searched: a point
  // that has since moved less than a tenth of a voxel keeps it (the current points are a half
  // voxel apart, so its nearest one rarely changes), which saves most of the searches once the
  // iterations settle.
  std::vector<int> match(source.size(), -1);
  std::vector<Eigen::Vector3d> searched_at(source.size());
  const double research2 = (0.1 * voxel) * (0.1 * voxel), max_r2 = o.max_residual * o.max_residual;
  for (int it = 0; it < o.max_iterations; ++it) {
    H.setZero();
    Vector6 g = Vector6::Zero();
    inliers = 0;
    wr2 = wsum = 0;
    for (size_t i = 0; i < source.size(); ++i) {
      if (!planes[i].valid) continue;
      const Eigen::Vector3d Rp = R * source[i];
      const Eigen::Vector3d q = Rp + t;
      int j = match[i];
      if (it == 0 || (q - searched_at[i]).squaredNorm() > research2) {
        double d2;
        j = current.nearest(q + c, &d2);
        if (j >= 0 && d2 > max_r2) j = -1;
        match[i] = j;
        searched_at[i] = q;
      } else if (j >= 0 && (q + c - target[j]).squaredNorm() > max_r2) {
        j = -1;
      }
      if (j < 0) continue;
      // The previous point's plane, turned with it: r = (R n) . (R p + t - x).
      const Eigen::Vector3d n = R * planes[i].normal;
      const Eigen::Vector3d d = q + c - target[j];
      const double r = n.dot(d);
      ++inliers;
      const double u = r / o.cauchy_scale, w = 1.0 / (1.0 + u * u);
      Vector6 J;
      // The normal turns with the point too ((R n) x d), but d's part along the plane is the
      // spacing of the current points, not a misalignment: left out, as in point-to-plane ICP.
      J << n, Rp.cross(n);
      if (o.planar) J.segment<3>(2).setZero();  // z, roll, pitch: not estimated, no information
      H.selfadjointView<Eigen::Lower>().rankUpdate(J, w);
      g += w * r * J;
      wr2 += w * r * r;
      wsum += w;
    }
    result.iterations = it + 1;
    if (inliers < 6) break;
    H.triangularView<Eigen::Upper>() = H.transpose();
    // A light damping keeps unmeasured directions where the prediction put them.
    Matrix6 A = H;
    A.diagonal().array() += 1e-6 * H.diagonal().maxCoeff() + 1e-9;
    Vector6 d = -A.ldlt().solve(g);
    // A step is at most max_step (m, and rad x 2 m): a direction the points hardly constrain must
    // not throw the estimate off in one step.
    const double len = std::max(d.head<3>().norm(), 2.0 * d.tail<3>().norm());
    if (len > o.max_step) d *= o.max_step / len;
    t += d.head<3>();
    R = expSO3(d.tail<3>()).toRotationMatrix() * R;
    if (d.head<3>().norm() + 2.0 * d.tail<3>().norm() < o.converged_step) break;
  }
  result.inliers = inliers;
  // Back to the world: M p = R (p - c) + t + c.
  result.motion.linear() = R;
  result.motion.translation() = t + c - R * c;
  if (inliers < std::max(6.0, o.min_inlier_fraction * static_cast<double>(source.size()))) {
    result.outcome = RegistrationOutcome::kPoorFit;
    return result;
  }
  result.rms_residual = std::sqrt(wr2 / std::max(wsum, 1e-12));
  // The centroid of the previous points moved this far from where the prediction put it.
  Eigen::Vector3d s = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : source) s += p;
  s /= static_cast<double>(source.size());
  if (((R * s + t) - (R0 * s + t0)).norm() > o.max_correction) {
    result.outcome = RegistrationOutcome::kDiverged;
    return result;
  }
  // The residuals' variance (robust-weighted, with the 6 fitted dimensions taken off), floored by
  // the sensor's noise.
  const double dof = std::max(1.0, wsum * (1.0 - 6.0 / std::max(7.0, static_cast<double>(inliers))));
  sigma2 = std::max(sigma2, wr2 / dof);
  Matrix6 info = H * (o.information_scale / sigma2);
  // Horizontal translation directions the points do not constrain: the marginal covariance of
  // (tx, ty), rotations and height included, has a standard deviation above max_sigma there (a
  // flat side seen edge-on: the motion along it). Their information is removed, not guessed.
  Matrix6 reg = info;
  reg.diagonal().array() += 1e-9 * std::max(1.0, info.diagonal().maxCoeff());
  const Matrix6 cov = reg.ldlt().solve(Matrix6::Identity());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(cov.topLeftCorner<2, 2>());
  int horizontal_dropped = 0;
  Matrix6 P = Matrix6::Identity();
  for (int k = 0; k < 2; ++k) {
    if (es.eigenvalues()[k] <= o.max_sigma * o.max_sigma) continue;
    ++horizontal_dropped;
    Eigen::Vector3d v = Eigen::Vector3d::Zero();
    v.head<2>() = es.eigenvectors().col(k);
    P.topLeftCorner<3, 3>() -= v * v.transpose();
  }
  if (horizontal_dropped >= 2) {
    result.outcome = RegistrationOutcome::kDegenerate;
    return result;
  }
  info = withAccuracyFloor(P.transpose() * info * P, o);
  // Centred tangent -> world tangent at M: dt_c = dt_w - [R c]x dtheta_w, dtheta_c = dtheta_w.
  Matrix6 G = Matrix6::Identity();
  G.block<3, 3>(0, 3) = -skew(R * c);
  result.information = G.transpose() * info * G;
  result.outcome = horizontal_dropped ? RegistrationOutcome::kPartial : RegistrationOutcome::kMeasured;
  return result;
}

}  // namespace dlslot::backend
