#include "backend/marginalization_prior.hpp"

#include "backend/pose_manifold.hpp"

namespace dlslot::backend {

MarginalizationPrior::MarginalizationPrior(std::vector<Vector7> x_lin, Eigen::MatrixXd J, Eigen::VectorXd r0,
                                           Eigen::MatrixXd H0, Eigen::VectorXd g0)
    : x_lin_(std::move(x_lin)), J_(std::move(J)), r0_(std::move(r0)), JtJ_(std::move(H0)), Jtr0_(std::move(g0)) {
  set_num_residuals(static_cast<int>(r0_.size()));
  for (size_t i = 0; i < x_lin_.size(); ++i) mutable_parameter_block_sizes()->push_back(kPoseSize);
  if (JtJ_.size() == 0) JtJ_.noalias() = J_.transpose() * J_;
  if (Jtr0_.size() == 0) Jtr0_.noalias() = J_.transpose() * r0_;
  const int n = numBlocks();
  upper_triangular_ = J_.rows() == 6 * n;
  for (int i = 1; i < n && upper_triangular_; ++i) upper_triangular_ = J_.block(6 * i, 0, 6, 6 * i).isZero(0.0);
}

MarginalizationPrior* MarginalizationPrior::CreatePosePrior(const Pose& x0, const Matrix6& sqrt_info) {
  return new MarginalizationPrior({toBlock(x0)}, sqrt_info, Eigen::VectorXd::Zero(6));
}

bool MarginalizationPrior::Evaluate(double const* const* x, double* residuals, double** jacobians) const {
  const int n = numBlocks();
  Eigen::VectorXd dx(kTangentSize * n);
  for (int i = 0; i < n; ++i) dx.segment<6>(6 * i) = minus(fromBlock(x[i]), fromBlock(x_lin_[i].data()));
  Eigen::Map<Eigen::VectorXd> r(residuals, numRows());
  r = r0_ + J_ * dx;
  if (!jacobians) return true;
  for (int i = 0; i < n; ++i) {
    if (!jacobians[i]) continue;
    const Matrix6 M = minusJacobianAt(fromBlock(x[i]), fromBlock(x_lin_[i].data()));
    const Eigen::MatrixXd J_tangent = J_.middleCols<6>(6 * i) * M;
    tangentRowsToAmbient(J_tangent, x[i], jacobians[i]);
  }
  return true;
}

bool MarginalizationPrior::evaluateRows(int i, double const* const* x, double* residuals, double** jacobians) const {
  // x holds blocks i..n-1; the rows of block i are zero in the columns of blocks 0..i-1.
  const int n = numBlocks();
  Eigen::VectorXd dx(kTangentSize * (n - i));
  std::vector<Pose> xs(n - i), lins(n - i);
  for (int k = i; k < n; ++k) {
    xs[k - i] = fromBlock(x[k - i]);
    lins[k - i] = fromBlock(x_lin_[k].data());
    dx.segment<6>(6 * (k - i)) = minus(xs[k - i], lins[k - i]);
  }
  const auto rows = J_.block(6 * i, 6 * i, 6, 6 * (n - i));
  Eigen::Map<Vector6> r(residuals);
  r = r0_.segment<6>(6 * i) + rows * dx;
  if (!jacobians) return true;
  for (int k = i; k < n; ++k) {
    if (!jacobians[k - i]) continue;
    const Matrix6 J_tangent = rows.middleCols<6>(6 * (k - i)) * minusJacobianAt(xs[k - i], lins[k - i]);
    tangentToAmbient(J_tangent, x[k - i], jacobians[k - i]);
  }
  return true;
}

namespace {

class PriorRows final : public ceres::CostFunction {
 public:
  PriorRows(const MarginalizationPrior& prior, int i) : prior_(prior), i_(i) {
    set_num_residuals(6);
    for (int k = i; k < prior.numBlocks(); ++k) mutable_parameter_block_sizes()->push_back(kPoseSize);
  }
  bool Evaluate(double const* const* x, double* residuals, double** jacobians) const override {
    return prior_.evaluateRows(i_, x, residuals, jacobians);
  }

 private:
  const MarginalizationPrior& prior_;
  int i_;
};

}  // namespace

std::unique_ptr<ceres::CostFunction> MarginalizationPrior::rowBlock(int i) const {
  return std::make_unique<PriorRows>(*this, i);
}

void MarginalizationPrior::linearize(double const* const* x, Eigen::MatrixXd& H, Eigen::VectorXd& g) const {
  const int n = numBlocks();
  Eigen::VectorXd dx(kTangentSize * n);
  std::vector<Matrix6> M(n);
  for (int i = 0; i < n; ++i) {
    const Pose xi = fromBlock(x[i]), li = fromBlock(x_lin_[i].data());
    dx.segment<6>(6 * i) = minus(xi, li);
    M[i] = minusJacobianAt(xi, li);
  }
  // Jx = J blockdiag(M): H = M^T (J^T J) M, g = M^T J^T (r0 + J dx).
  const Eigen::VectorXd g0 = Jtr0_ + JtJ_ * dx;
  H.resize(6 * n, 6 * n);
  g.resize(6 * n);
  for (int i = 0; i < n; ++i) {
    g.segment<6>(6 * i) = M[i].transpose() * g0.segment<6>(6 * i);
    for (int j = 0; j < n; ++j)
      H.block<6, 6>(6 * i, 6 * j) = M[i].transpose() * JtJ_.block<6, 6>(6 * i, 6 * j) * M[j];
  }
}

}  // namespace dlslot::backend
