// The Gauss-Newton terms of one factor at the current values of its blocks, shared by the
// WindowSolver and the Marginalizer: per estimated block the tangent Jacobian, the residual,
// and a robust loss applied as Ceres applies it. A MarginalizationPrior gives H = J^T J and
// g = J^T r directly (its rows are dense; forming J^T J again would cost more than the rest).
#pragma once

#include <Eigen/Core>
#include <unordered_set>
#include <vector>

#include "backend/factor.hpp"
#include "backend/se3.hpp"

namespace dlslot::backend {

// Every factor but the prior has a 6-dimensional residual (an SE(3) error), so fixed sizes.
struct FactorLinearization {
  Vector6 r = Vector6::Zero();           // residual (robust loss applied)
  std::vector<Matrix6> J;                // per block: tangent Jacobian
  std::vector<bool> estimated;           // per block: false when fixed (J unused)
  bool is_prior = false;                 // then H and g below instead of r and J
  Eigen::MatrixXd H;                     // 6n x 6n over the prior's blocks (fixed ones zero)
  Eigen::VectorXd g;
};

FactorLinearization linearize(const Factor& f, const std::unordered_set<const double*>& fixed);

// 0.5 * rho(|r|^2) at the current values (Ceres' cost of a residual block).
double factorCost(const Factor& f);

}  // namespace dlslot::backend
