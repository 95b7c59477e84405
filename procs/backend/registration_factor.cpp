#include "backend/registration_factor.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

namespace dlslot::backend {

namespace {

// [[I, -[t]x], [0, I]]: a left perturbation of P carried to that of P Q (t = R_P t_Q).
Matrix6 leftOfProduct(const Eigen::Vector3d& t) {
  Matrix6 T = Matrix6::Identity();
  T.topRightCorner<3, 3>() = -skew(t);
  return T;
}

}  // namespace

Vector6 RegistrationFactor::error(double const* const* x, Matrix6* const* d) const {
  const Pose X_prev = fromBlock(x[0]), X_cur = fromBlock(x[1]), o = fromBlock(x[2]), c = fromBlock(x[3]);
  const Pose o_inv = o.inverse();
  const Pose M = o * c * o_inv;
  const Pose B = X_cur * A_meas_;
  Matrix6 dM, dB;
  const Vector6 e = relativeError(M, B, X_prev, (d[2] || d[3]) ? &dM : nullptr, d[1] ? &dB : nullptr, d[0]);
  // X_t in B = X_t A_meas.
  if (d[1]) *d[1] = dB * leftOfProduct(X_cur.linear() * A_meas_.translation());
  if (d[2]) {
    // o in M = o c o^-1: o -> D o with D = (Exp(p), dp + [t_o]x p) turns M into D M D^-1, whose
    // left perturbation is ((I - R_M) t_D - [t_M]x p, (I - R_M) p).
    const Eigen::Matrix3d I_RM = Eigen::Matrix3d::Identity() - M.linear();
    Matrix6 T = Matrix6::Zero();
    T.topLeftCorner<3, 3>() = I_RM;
    T.topRightCorner<3, 3>() = I_RM * skew(o.translation()) - skew(M.translation());
    T.bottomRightCorner<3, 3>() = I_RM;
    *d[2] = dM * T;
  }
  if (d[3]) {
    // c in M = o c o^-1: (R_o dq - R_o [R_c t_{o^-1}]x q, R_o q).
    const Eigen::Matrix3d& R_o = o.linear();
    Matrix6 T = Matrix6::Zero();
    T.topLeftCorner<3, 3>() = R_o;
    T.topRightCorner<3, 3>() = -R_o * skew(c.linear() * o_inv.translation());
    T.bottomRightCorner<3, 3>() = R_o;
    *d[3] = dM * T;
  }
  return e;
}

RegistrationMeasurement registrationMeasurement(const Pose& M, const Matrix6& information, const Pose& X_prev,
                                                const Pose& X_cur) {
  RegistrationMeasurement out;
  out.A_meas = X_cur.inverse() * M * X_prev;
  // e = (X_cur A_meas)^-1 M' X_prev, whose Jacobian in M' at M is relativeError's dA.
  Matrix6 G;
  relativeError(M, X_cur * out.A_meas, X_prev, &G, nullptr, nullptr);
  // Info_e = G^-T Info_M G^-1 (G is invertible: conjugations and a left Jacobian), and
  // S = sqrt(Lambda) V^T with S^T S = Info_e (rank-deficient where M was not measured).
  const Matrix6 Gi = G.inverse();
  const Matrix6 info = Gi.transpose() * information * Gi;
  Eigen::SelfAdjointEigenSolver<Matrix6> es(0.5 * (info + info.transpose()));
  out.sqrt_info = es.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal() * es.eigenvectors().transpose();
  return out;
}

}  // namespace dlslot::backend
