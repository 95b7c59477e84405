// SE(3) helpers for the backend's pose states. A pose state block holds 7 doubles
// [tx ty tz qx qy qz qw] (T_world_x: translation, then an Eigen-ordered unit quaternion); its
// tangent is [dt; dtheta] with the rotation perturbed on the left in the world frame:
// x [+] d = (t + dt, Exp(dtheta) * R). Residuals of SE(3) errors are [t_e; Log(R_e)].
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "dlslot/types.hpp"

namespace dlslot::backend {

constexpr int kPoseSize = 7;     // ambient size of a pose block
constexpr int kTangentSize = 6;  // its tangent size

using Vector6 = Eigen::Matrix<double, 6, 1>;
using Matrix6 = Eigen::Matrix<double, 6, 6>;
using Vector7 = Eigen::Matrix<double, 7, 1>;
// A Jacobian with respect to the 7 ambient coordinates of a pose block, row-major as Ceres wants.
using Matrix67 = Eigen::Matrix<double, 6, 7, Eigen::RowMajor>;

Eigen::Matrix3d skew(const Eigen::Vector3d& v);
// Exp and Log of SO(3) with the full rotation angle (|phi| = angle in radians).
Eigen::Quaterniond expSO3(const Eigen::Vector3d& phi);
Eigen::Vector3d logSO3(const Eigen::Quaterniond& q);
// Inverse of the left Jacobian: Exp(d) Exp(phi) = Exp(phi + Jl^-1(phi) d) to first order.
Eigen::Matrix3d leftJacobianInverse(const Eigen::Vector3d& phi);

Vector7 toBlock(const Pose& T);
void toBlock(const Pose& T, double* block);
Pose fromBlock(const double* block);

// [t; Log(R)] of a pose: the residual of an SE(3) error (identity -> 0).
Vector6 logPose(const Pose& T);
// x [+] d and y [-] x on pose blocks (the PoseManifold's Plus and Minus).
Pose plus(const Pose& x, const Vector6& d);
Vector6 minus(const Pose& y, const Pose& x);

// The error e = B^-1 * A * Z shared by every factor (eq. 8-11 all have this form, e.g. eq. 8:
// (X_{t-1}^-1 X_t)^-1 T = X_t^-1 X_{t-1} T), with its residual [t_e; Log(R_e)] and the
// Jacobians of that residual with respect to tangent perturbations of A, B and Z (any may be
// null).
Vector6 relativeError(const Pose& A, const Pose& B, const Pose& Z, Matrix6* dA, Matrix6* dB, Matrix6* dZ);

// d (y [-] x_lin) / d(tangent of y) at y: blockdiag(I, Jl^-1(Log(R_y R_lin^T))).
Matrix6 minusJacobianAt(const Pose& y, const Pose& x_lin);

}  // namespace dlslot::backend
