// The Gauss-Newton terms of one factor at the current values of its blocks, shared by the
// WindowSolver and the Marginalizer: per estimated block the tangent Jacobian, the residual,
// and a robust loss applied as Ceres applies it. A MarginalizationPrior gives its gradient and
// manifold corrections instead (its rows are dense; forming J^T J again would cost more than
// the rest), and both kinds answer the same block questions.
#pragma once

#include <Eigen/Core>
#include <unordered_set>
#include <vector>

#include "backend/factor.hpp"
#include "backend/se3.hpp"

namespace dlslot::backend {

class MarginalizationPrior;

struct FactorLinearization {
  // Every factor but the prior has a 6-dimensional residual (an SE(3) error), so fixed sizes.
  Vector6 r = Vector6::Zero();   // residual (robust loss applied)
  double cost = 0;               // the factor's cost at the linearization point (factorCost)
  std::vector<Matrix6> J;        // per block: tangent Jacobian
  std::vector<bool> estimated;   // per block: false when fixed (its terms are zero)
  const MarginalizationPrior* prior = nullptr;  // a prior: g and M below instead of r and J
  Eigen::VectorXd g;             // prior: gradient over its blocks
  std::vector<Matrix6> M;        // prior: manifold corrections (MarginalizationPrior::gradient)

  Vector6 gradientBlock(int a) const;
  // Block (a, b) of the Gauss-Newton model's Hessian J^T J (fixed blocks' are not
  // meaningful): users form only the blocks they keep.
  Matrix6 hessianBlock(int a, int b) const;
  // The model's predicted cost decrease for a step (per block, fixed ones ignored):
  // -(g . dx + 0.5 dx^T H dx).
  double modelDecrease(const std::vector<Vector6>& dx) const;
};

// Into `lin`, reusing its storage (the solver linearizes every factor at every step).
void linearize(const Factor& f, const std::unordered_set<const double*>& fixed, FactorLinearization& lin);

// 0.5 * rho(|r|^2) at the current values (Ceres' cost of a residual block).
double factorCost(const Factor& f);

}  // namespace dlslot::backend
