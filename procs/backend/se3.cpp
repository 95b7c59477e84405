#include "backend/se3.hpp"

#include <cmath>

namespace dlslot::backend {

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d S;
  S << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return S;
}

Eigen::Quaterniond expSO3(const Eigen::Vector3d& phi) {
  const double theta = phi.norm();
  // sin(theta/2)/theta -> 1/2 - theta^2/48 as theta -> 0.
  const double k = theta < 1e-8 ? 0.5 - theta * theta / 48.0 : std::sin(0.5 * theta) / theta;
  return Eigen::Quaterniond(std::cos(0.5 * theta), k * phi.x(), k * phi.y(), k * phi.z());
}

Eigen::Vector3d logSO3(const Eigen::Quaterniond& q_in) {
  // q and -q are the same rotation; take w >= 0 so the angle is in [0, pi].
  const Eigen::Quaterniond q = q_in.w() < 0 ? Eigen::Quaterniond(-q_in.coeffs()) : q_in;
  const double s = q.vec().norm();
  // angle / sin(angle/2) = 2 atan2(s, w) / s -> 2 / w as s -> 0.
  const double k = s < 1e-10 ? 2.0 / q.w() : 2.0 * std::atan2(s, q.w()) / s;
  return k * q.vec();
}

Eigen::Matrix3d leftJacobianInverse(const Eigen::Vector3d& phi) {
  const double theta = phi.norm();
  const Eigen::Matrix3d P = skew(phi);
  double c;
  if (theta < 1e-5) {
    c = 1.0 / 12.0;  // limit of the coefficient below
  } else {
    c = 1.0 / (theta * theta) - (1.0 + std::cos(theta)) / (2.0 * theta * std::sin(theta));
  }
  return Eigen::Matrix3d::Identity() - 0.5 * P + c * P * P;
}

Vector7 toBlock(const Pose& T) {
  Vector7 x;
  toBlock(T, x.data());
  return x;
}

void toBlock(const Pose& T, double* block) {
  const Eigen::Quaterniond q(T.linear());
  Eigen::Map<Eigen::Vector3d> t(block);
  Eigen::Map<Eigen::Quaterniond> q_out(block + 3);
  t = T.translation();
  q_out = q.normalized();
}

Pose fromBlock(const double* block) {
  Pose T = Pose::Identity();
  T.linear() = Eigen::Map<const Eigen::Quaterniond>(block + 3).normalized().toRotationMatrix();
  T.translation() = Eigen::Map<const Eigen::Vector3d>(block);
  return T;
}

Vector6 logPose(const Pose& T) {
  Vector6 r;
  r.head<3>() = T.translation();
  r.tail<3>() = logSO3(Eigen::Quaterniond(T.linear()));
  return r;
}

Pose plus(const Pose& x, const Vector6& d) {
  Pose y = Pose::Identity();
  y.linear() = (expSO3(d.tail<3>()) * Eigen::Quaterniond(x.linear())).normalized().toRotationMatrix();
  y.translation() = x.translation() + d.head<3>();
  return y;
}

Vector6 minus(const Pose& y, const Pose& x) {
  Vector6 d;
  d.head<3>() = y.translation() - x.translation();
  d.tail<3>() = logSO3(Eigen::Quaterniond(y.linear() * x.linear().transpose()));
  return d;
}

Vector6 relativeError(const Pose& A, const Pose& B, const Pose& Z, Matrix6* dA, Matrix6* dB, Matrix6* dZ) {
  const Eigen::Matrix3d RBt = B.linear().transpose();
  const Eigen::Matrix3d RA = A.linear();
  const Eigen::Vector3d RA_tZ = RA * Z.translation();
  const Eigen::Vector3d w = RA_tZ + A.translation() - B.translation();
  Vector6 r;
  r.head<3>() = RBt * w;
  r.tail<3>() = logSO3(Eigen::Quaterniond(RBt * RA * Z.linear()));
  if (!dA && !dB && !dZ) return r;

  // Left perturbations: A -> (Exp(a) R_A, t_A + da) moves R_e to Exp(R_B^T a) R_e, and
  // Log(Exp(d) R_e) = Log(R_e) + Jl^-1 d; translations follow from t_e = R_B^T w.
  const Eigen::Matrix3d Jinv = leftJacobianInverse(r.tail<3>());
  if (dA) {
    dA->setZero();
    dA->topLeftCorner<3, 3>() = RBt;
    dA->topRightCorner<3, 3>() = -RBt * skew(RA_tZ);
    dA->bottomRightCorner<3, 3>() = Jinv * RBt;
  }
  if (dB) {
    dB->setZero();
    dB->topLeftCorner<3, 3>() = -RBt;
    dB->topRightCorner<3, 3>() = RBt * skew(w);
    dB->bottomRightCorner<3, 3>() = -Jinv * RBt;
  }
  if (dZ) {
    const Eigen::Matrix3d RBt_RA = RBt * RA;
    dZ->setZero();
    dZ->topLeftCorner<3, 3>() = RBt_RA;
    dZ->bottomRightCorner<3, 3>() = Jinv * RBt_RA;
  }
  return r;
}

Matrix6 minusJacobianAt(const Pose& y, const Pose& x_lin) {
  Matrix6 M = Matrix6::Identity();
  M.bottomRightCorner<3, 3>() =
      leftJacobianInverse(logSO3(Eigen::Quaterniond(y.linear() * x_lin.linear().transpose())));
  return M;
}

}  // namespace dlslot::backend
