// The prior left by marginalization (paper III-C: "applying Schur complement ... can reserve
// the constraint that will be slided out of the window"), as in VINS-Mono: a linear residual
//   r(x) = r0 + J (x [-] x_lin)
// on the pose blocks that remain, with J and r0 from the Schur complement and x_lin the values
// at which it was linearized. J stays fixed afterwards (first-estimate Jacobian), so the prior
// never changes its information when its states move; only the manifold's own [-] is exact.
#pragma once

#include <ceres/cost_function.h>

#include <vector>

#include "backend/dense_kernels.hpp"
#include "backend/se3.hpp"

namespace dlslot::backend {

class MarginalizationPrior final : public ceres::CostFunction {
 public:
  // x_lin: one linearization point per block; J: rows x (6 * blocks); r0: rows. H0 = J^T J
  // and g0 = J^T r0 when the caller has them (the Marginalizer does), else computed.
  // (J is kept row-major: the Marginalizer's Cholesky factor L is J^T column-major, the same
  // storage.)
  MarginalizationPrior(std::vector<Vector7> x_lin, dense::RowMatrix J, Eigen::VectorXd r0,
                       Eigen::MatrixXd H0 = Eigen::MatrixXd(), Eigen::VectorXd g0 = Eigen::VectorXd());
  // A prior on a single pose (e.g. the first ego pose, which fixes the gauge): r = S (x [-] x0).
  static MarginalizationPrior* CreatePosePrior(const Pose& x0, const Matrix6& sqrt_info);

  bool Evaluate(double const* const* x, double* residuals, double** jacobians) const override;

  // The Gauss-Newton terms at x in the blocks' tangent spaces, without forming Jx^T Jx from the
  // dense rows: Jx = J blockdiag(M) with M_i = d(x_i [-] x_lin_i)/dx_i, so the gradient is
  // g = M^T (J^T r0 + J^T J dx) and the Hessian blockdiag(M)^T (J^T J) blockdiag(M), formed
  // only when a solver needs it. J^T J and J^T r0 are kept from construction. Returns the
  // cost 0.5 |r(x)|^2 = 0.5 |r0|^2 + 0.5 dx . (J^T r0 + J^T J dx + J^T r0), dx = x [-] x_lin.
  double gradient(double const* const* x, std::vector<Matrix6>& M, Eigen::VectorXd& g) const;
  void hessian(const std::vector<Matrix6>& M, Eigen::MatrixXd& H) const;
  // Its 6x6 block (i, j), for solvers that keep only some blocks.
  Matrix6 hessianBlock(const std::vector<Matrix6>& M, int i, int j) const;
  // The whole H = Jx^T Jx and g = Jx^T r(x) (for tests and small priors).
  void linearize(double const* const* x, Eigen::MatrixXd& H, Eigen::VectorXd& g) const;
  // |Jx dx|^2 for a tangent step dx over every block.
  double curvature(const std::vector<Matrix6>& M, const Eigen::VectorXd& dx) const;

  int numBlocks() const { return static_cast<int>(x_lin_.size()); }
  int numRows() const { return static_cast<int>(r0_.size()); }
  const std::vector<Vector7>& linearizationPoints() const { return x_lin_; }

 private:
  std::vector<Vector7> x_lin_;
  dense::RowMatrix J_;
  Eigen::VectorXd r0_;
  Eigen::MatrixXd JtJ_;
  Eigen::VectorXd Jtr0_;
  double half_r0_squared_ = 0;
};

}  // namespace dlslot::backend
