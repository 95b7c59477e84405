// The 6 numbers Ceres optimizes for a rigid motion T_ref_cur: x = [t; w], with
// p_ref = Exp(w) p_cur + t (w a rotation vector). Registration keeps x near zero by expressing
// the reference geometry in the frame of the current guess, so no manifold is needed.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "dlslot/types.hpp"

namespace dlslot::odometry {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix36d = Eigen::Matrix<double, 3, 6>;

inline Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

inline Eigen::Matrix3d expSO3(const Eigen::Vector3d& w) {
  const double theta = w.norm();
  if (theta < 1e-12) return Eigen::Matrix3d::Identity() + skew(w);
  return Eigen::AngleAxisd(theta, w / theta).toRotationMatrix();
}

// Left Jacobian of SO(3): Exp(w + dw) ~= Exp(J_l(w) dw) Exp(w).
inline Eigen::Matrix3d leftJacobianSO3(const Eigen::Vector3d& w) {
  const double theta2 = w.squaredNorm();
  const Eigen::Matrix3d W = skew(w);
  if (theta2 < 1e-10) return Eigen::Matrix3d::Identity() + 0.5 * W + W * W / 6.0;
  const double theta = std::sqrt(theta2);
  return Eigen::Matrix3d::Identity() + (1.0 - std::cos(theta)) / theta2 * W +
         (theta - std::sin(theta)) / (theta2 * theta) * W * W;
}

inline Pose poseFromParams(const double* x) {
  Pose T = Pose::Identity();
  T.linear() = expSO3(Eigen::Vector3d(x[3], x[4], x[5]));
  T.translation() = Eigen::Vector3d(x[0], x[1], x[2]);
  return T;
}

// The same pose with its rotation made exactly orthonormal. Isometry3d::inverse() assumes an
// orthonormal rotation; chained poses (pose = guess * correction, velocity = last^-1 * pose)
// otherwise amplify rounding errors frame after frame until the rotation is no rotation at all.
inline Pose orthonormalized(const Pose& T) {
  Pose out = Pose::Identity();
  out.linear() = Eigen::Quaterniond(T.linear()).normalized().toRotationMatrix();
  out.translation() = T.translation();
  return out;
}

// x = [t; w] evaluated once for many points: p_ref = Exp(w) p + t and, when J is given, its
// Jacobian d p_ref / d x = [I, -[Exp(w) p]x J_l(w)]. Ceres evaluates all residual blocks of a
// registration at the same x in a row (single-threaded), so they share one RigidMotion and the
// rotation and its Jacobian are computed once per x, not once per point.
class RigidMotion {
 public:
  const RigidMotion& at(const double* x) {
    if (!std::equal(x, x + 6, x_)) {
      std::copy(x, x + 6, x_);
      const Eigen::Vector3d w(x[3], x[4], x[5]);
      R_ = expSO3(w);
      Jl_ = leftJacobianSO3(w);
      t_ = Eigen::Vector3d(x[0], x[1], x[2]);
    }
    return *this;
  }
  Eigen::Vector3d apply(const Eigen::Vector3d& p, Matrix36d* J) const {
    const Eigen::Vector3d Rp = R_ * p;
    if (J) {
      J->leftCols<3>().setIdentity();
      J->rightCols<3>() = -skew(Rp) * Jl_;
    }
    return Rp + t_;
  }
  const Eigen::Matrix3d& rotation() const { return R_; }
  const Eigen::Vector3d& translation() const { return t_; }
  const Eigen::Matrix3d& leftJacobian() const { return Jl_; }

 private:
  double x_[6] = {NAN, NAN, NAN, NAN, NAN, NAN};  // never equal: the first at() computes
  Eigen::Matrix3d R_, Jl_;
  Eigen::Vector3d t_;
};

}  // namespace dlslot::odometry
