#include "backend/registered_velocity.hpp"

#include <cmath>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include "backend/registration_factor.hpp"

namespace dlslot::backend {

std::optional<VelocityEvidence> registeredVelocity(const Pose& M, const Matrix6& information,
                                                   const Eigen::Vector3d& p_prev, double dt, double ego_sigma_m,
                                                   double change_sigma_mps) {
  if (!(dt > 0)) return std::nullopt;
  // The measurement as a pose change of a frame at the centre with the world's axes: its
  // translation is the centre's displacement, in world axes.
  Pose o = Pose::Identity();
  o.translation() = p_prev;
  const RegistrationMeasurement pm = registrationMeasurement(M, information, o, o);
  const Matrix6 info = pm.sqrt_info.transpose() * pm.sqrt_info;
  // The registration measures the ground plane only (x, y, yaw): the yaw marginalized (Schur
  // complement) out of that block. Height, roll and pitch carry no information; their
  // numerically tiny entries must not enter a pseudo-inverse.
  const double yy = info(5, 5);
  Eigen::Matrix2d tt = info.topLeftCorner<2, 2>();
  if (yy > 0) tt -= info.block<2, 1>(0, 5) * info.block<1, 2>(5, 0) / yy;
  // Bird's-eye displacement information, each measured direction's variance grown by the ego's.
  // e's translation is in the measured change's axes (turned by its yaw): back to the world's.
  const Eigen::Matrix2d R = pm.A_meas.linear().topLeftCorner<2, 2>();
  tt = R * tt * R.transpose();
  Eigen::Matrix2d d_info = 0.5 * (tt + tt.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> ed(d_info);
  Eigen::Matrix2d info_v = Eigen::Matrix2d::Zero();
  const double d_max = std::max(ed.eigenvalues().maxCoeff(), 0.0);
  if (!(d_max > 0)) return std::nullopt;
  for (int k = 0; k < 2; ++k) {
    const double lambda = ed.eigenvalues()[k];
    if (!(lambda > 1e-9 * d_max)) continue;
    const double var_v = (1.0 / lambda + ego_sigma_m * ego_sigma_m) / (dt * dt) + change_sigma_mps * change_sigma_mps;
    info_v += ed.eigenvectors().col(k) * ed.eigenvectors().col(k).transpose() / var_v;
  }
  VelocityEvidence v;
  v.velocity = ((M * p_prev - p_prev) / dt).head<2>();
  v.information = info_v;
  return v;
}

FusedVelocity fuseVelocities(const Eigen::Vector2d& line_velocity, const Eigen::Matrix2d& line_covariance,
                             const std::vector<VelocityEvidence>& registered) {
  const Eigen::Matrix2d line_info = line_covariance.inverse();
  Eigen::Matrix2d info = line_info;
  Eigen::Vector2d eta = line_info * line_velocity;
  int used = 0;
  for (const VelocityEvidence& r : registered) {
    // The disagreement in the measured directions (the registration's range): d^T (P C P^T + I^-1)^+ d,
    // from the eigen-directions of its information.
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(r.information);
    const double max_l = es.eigenvalues().maxCoeff();
    double chi2 = 0;
    int dof = 0;
    for (int k = 0; k < 2; ++k) {
      const double l = es.eigenvalues()[k];
      if (!(l > 1e-9 * max_l)) continue;
      const Eigen::Vector2d u = es.eigenvectors().col(k);
      const double d = u.dot(r.velocity - line_velocity);
      chi2 += d * d / (1.0 / l + u.dot(line_covariance * u));
      ++dof;
    }
    // 99 % quantiles of chi-square with 1 and 2 degrees of freedom.
    if (dof == 0 || chi2 > (dof == 1 ? 6.63 : 9.21)) continue;
    info += r.information;
    eta += r.information * r.velocity;
    ++used;
  }
  FusedVelocity out;
  out.velocity = info.ldlt().solve(eta);
  out.covariance = info.inverse();
  out.used = used;
  return out;
}

bool measuredMotion(const std::vector<VelocityEvidence>& evidence, double min_speed, double min_sigmas) {
  Eigen::Matrix2d info = Eigen::Matrix2d::Zero();
  Eigen::Vector2d eta = Eigen::Vector2d::Zero();
  for (const VelocityEvidence& e : evidence) {
    info += e.information;
    eta += e.information * e.velocity;
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(0.5 * (info + info.transpose()));
  for (int k = 0; k < 2; ++k) {
    const double l = es.eigenvalues()[k];
    if (!(l > 0)) continue;
    const double speed = std::abs(es.eigenvectors().col(k).dot(eta)) / l;  // along it, sigma 1 / sqrt(l)
    if (speed > min_speed && speed > min_sigmas / std::sqrt(l)) return true;
  }
  return false;
}

}  // namespace dlslot::backend
