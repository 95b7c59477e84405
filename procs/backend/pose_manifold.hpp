// The SE(3) state manifold of every pose block (ego poses X, object poses o, pose changes c,
// landmarks): ambient [t; q] (7), tangent [dt; dtheta] (6), x [+] d = (t + dt, Exp(dtheta) q).
// The rotation tangent is the full angle (unlike ceres::EigenQuaternionManifold's half angle),
// so covariances come out in metres and radians.
#pragma once

#include <ceres/manifold.h>

#include "backend/se3.hpp"

namespace dlslot::backend {

class PoseManifold final : public ceres::Manifold {
 public:
  int AmbientSize() const override { return kPoseSize; }
  int TangentSize() const override { return kTangentSize; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;

  // The same Jacobians as fixed-size matrices (7x6 and 6x7, row-major like Ceres).
  static Eigen::Matrix<double, 7, 6, Eigen::RowMajor> plusJacobian(const double* x);
  static Matrix67 minusJacobian(const double* x);
};

// Ceres takes Jacobians with respect to the ambient coordinates and multiplies them by
// PlusJacobian(x); J_tangent * MinusJacobian(x) is such a Jacobian, because
// MinusJacobian(x) * PlusJacobian(x) = I. Writes the rows x 7 row-major result to `out`.
void tangentToAmbient(const Matrix6& J_tangent, const double* x, double* out);
void tangentRowsToAmbient(const Eigen::Ref<const Eigen::MatrixXd>& J_tangent, const double* x, double* out);

}  // namespace dlslot::backend
