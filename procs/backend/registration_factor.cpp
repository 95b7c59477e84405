#include "backend/registration_factor.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

namespace dlslot::backend {

PoseChangeMeasurement poseChangeMeasurement(const Pose& M, const Matrix6& information, const Pose& o_prev) {
  PoseChangeMeasurement out;
  const Pose o_inv = o_prev.inverse();
  out.c_meas = o_inv * M * o_prev;
  const Pose c_inv = out.c_meas.inverse();
  // G = de/dd: e(d) = Log(c_meas^-1 o^-1 (M [+] d) o), central differences.
  Matrix6 G;
  const double h = 1e-6;
  for (int k = 0; k < 6; ++k) {
    Vector6 d = Vector6::Zero();
    d[k] = h;
    G.col(k) = (logPose(c_inv * o_inv * plus(M, d) * o_prev) - logPose(c_inv * o_inv * plus(M, -d) * o_prev)) / (2 * h);
  }
  // Info_e = G^-T Info_M G^-1 (G is invertible: conjugation by o_prev), and S^T S = Info_e with
  // S = sqrt(Lambda) V^T (Info_e may be rank-deficient).
  const Matrix6 Gi = G.inverse();
  Matrix6 info = Gi.transpose() * information * Gi;
  info = 0.5 * (info + info.transpose());
  Eigen::SelfAdjointEigenSolver<Matrix6> es(info);
  const Vector6 lambda = es.eigenvalues().cwiseMax(0.0);
  out.sqrt_info = lambda.cwiseSqrt().asDiagonal() * es.eigenvectors().transpose();
  return out;
}

}  // namespace dlslot::backend
