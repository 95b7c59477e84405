// The base of every factor of eq. 8-11: a whitened SE(3) error r = S e over 1 to 4 pose blocks,
// e = B^-1 A Z from relativeError with analytic tangent Jacobians. evaluate() gives r and the
// tangent Jacobians the WindowSolver and Marginalizer use directly; Evaluate() turns them into
// the ambient Jacobians Ceres wants (tests compare against Ceres' own solver with it).
#pragma once

#include <ceres/cost_function.h>

#include "backend/pose_manifold.hpp"

namespace dlslot::backend {

class PoseFactor : public ceres::CostFunction {
 public:
  static constexpr int kMaxBlocks = 4;

  PoseFactor(int num_blocks, const Matrix6& sqrt_info) : sqrt_info_(sqrt_info) {
    set_num_residuals(6);
    for (int k = 0; k < num_blocks; ++k) mutable_parameter_block_sizes()->push_back(kPoseSize);
  }

  // r = S e, and J[k] = dr/d(tangent of block k) where J[k] is not null (J may be null).
  Vector6 evaluate(double const* const* x, Matrix6* const* J) const {
    Matrix6 d[kMaxBlocks];
    Matrix6* dp[kMaxBlocks] = {};
    const int n = static_cast<int>(parameter_block_sizes().size());
    for (int k = 0; k < n; ++k)
      if (J && J[k]) dp[k] = &d[k];
    const Vector6 r = sqrt_info_ * error(x, dp);
    for (int k = 0; k < n; ++k)
      if (dp[k]) J[k]->noalias() = sqrt_info_ * d[k];
    return r;
  }

  bool Evaluate(double const* const* x, double* residuals, double** jacobians) const final {
    Matrix6 J[kMaxBlocks];
    Matrix6* Jp[kMaxBlocks] = {};
    const int n = static_cast<int>(parameter_block_sizes().size());
    for (int k = 0; k < n; ++k)
      if (jacobians && jacobians[k]) Jp[k] = &J[k];
    Eigen::Map<Vector6> r(residuals);
    r = evaluate(x, Jp);
    for (int k = 0; k < n; ++k)
      if (Jp[k]) tangentToAmbient(J[k], x[k], jacobians[k]);
    return true;
  }

 protected:
  // The whitening of a factor with a single residual, e[0] with standard deviation sigma.
  static Matrix6 scalarWhitening(double sigma) {
    Matrix6 S = Matrix6::Zero();
    S(0, 0) = 1.0 / sigma;
    return S;
  }
  // The unwhitened error and its tangent Jacobians d[k] (where not null).
  virtual Vector6 error(double const* const* x, Matrix6* const* d) const = 0;

 private:
  Matrix6 sqrt_info_;
};

}  // namespace dlslot::backend
