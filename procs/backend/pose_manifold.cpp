#include "backend/pose_manifold.hpp"

namespace dlslot::backend {

bool PoseManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  Eigen::Map<const Eigen::Vector3d> t(x), dt(delta), dtheta(delta + 3);
  Eigen::Map<const Eigen::Quaterniond> q(x + 3);
  Eigen::Map<Eigen::Vector3d> t_out(x_plus_delta);
  Eigen::Map<Eigen::Quaterniond> q_out(x_plus_delta + 3);
  t_out = t + dt;
  q_out = (expSO3(dtheta) * q).normalized();
  return true;
}

Eigen::Matrix<double, 7, 6, Eigen::RowMajor> PoseManifold::plusJacobian(const double* x) {
  // d(Exp(d) q)/dd at d = 0 with q = (v, w): dv = (w I - [v]x) d / 2, dw = -v.d / 2.
  const Eigen::Vector3d v(x[3], x[4], x[5]);
  const double w = x[6];
  Eigen::Matrix<double, 7, 6, Eigen::RowMajor> J = Eigen::Matrix<double, 7, 6, Eigen::RowMajor>::Zero();
  J.topLeftCorner<3, 3>().setIdentity();
  J.block<3, 3>(3, 3) = 0.5 * (w * Eigen::Matrix3d::Identity() - skew(v));
  J.block<1, 3>(6, 3) = -0.5 * v.transpose();
  return J;
}

Matrix67 PoseManifold::minusJacobian(const double* x) {
  // d Log(y x^-1)/dy at y = x: 2 d vec(y x^-1)/dy = 2 [w I + [v]x, -v] (columns qx qy qz qw).
  const Eigen::Vector3d v(x[3], x[4], x[5]);
  const double w = x[6];
  Matrix67 J = Matrix67::Zero();
  J.topLeftCorner<3, 3>().setIdentity();
  J.block<3, 3>(3, 3) = 2.0 * (w * Eigen::Matrix3d::Identity() + skew(v));
  J.block<3, 1>(3, 6) = -2.0 * v;
  return J;
}

bool PoseManifold::PlusJacobian(const double* x, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, 7, 6, Eigen::RowMajor>> J(jacobian);
  J = plusJacobian(x);
  return true;
}

bool PoseManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  Eigen::Map<const Eigen::Quaterniond> qy(y + 3), qx(x + 3);
  Eigen::Map<Eigen::Vector3d> dt(y_minus_x), dtheta(y_minus_x + 3);
  dt = Eigen::Map<const Eigen::Vector3d>(y) - Eigen::Map<const Eigen::Vector3d>(x);
  dtheta = logSO3(qy * qx.conjugate());
  return true;
}

bool PoseManifold::MinusJacobian(const double* x, double* jacobian) const {
  Eigen::Map<Matrix67> J(jacobian);
  J = minusJacobian(x);
  return true;
}

void tangentToAmbient(const Matrix6& J_tangent, const double* x, double* out) {
  Eigen::Map<Matrix67> J(out);
  J.noalias() = J_tangent * PoseManifold::minusJacobian(x);
}

void tangentRowsToAmbient(const Eigen::Ref<const Eigen::MatrixXd>& J_tangent, const double* x, double* out) {
  Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 7, Eigen::RowMajor>> J(out, J_tangent.rows(), 7);
  J.noalias() = J_tangent * PoseManifold::minusJacobian(x);
}

}  // namespace dlslot::backend
