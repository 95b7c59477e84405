#include "backend/marginalization_prior.hpp"

#include "backend/pose_manifold.hpp"

namespace dlslot::backend {

MarginalizationPrior::MarginalizationPrior(std::vector<Vector7> x_lin, dense::RowMatrix J, Eigen::VectorXd r0,
                                           Eigen::MatrixXd H0, Eigen::VectorXd g0)
    : x_lin_(std::move(x_lin)), J_(std::move(J)), r0_(std::move(r0)), JtJ_(std::move(H0)), Jtr0_(std::move(g0)) {
  set_num_residuals(static_cast<int>(r0_.size()));
  for (size_t i = 0; i < x_lin_.size(); ++i) mutable_parameter_block_sizes()->push_back(kPoseSize);
  if (JtJ_.size() == 0) JtJ_.noalias() = J_.transpose() * J_;
  if (Jtr0_.size() == 0) Jtr0_.noalias() = J_.transpose() * r0_;
  half_r0_squared_ = 0.5 * r0_.squaredNorm();
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

double MarginalizationPrior::gradient(double const* const* x, std::vector<Matrix6>& M, Eigen::VectorXd& g) const {
  const int n = numBlocks();
  Eigen::VectorXd dx(kTangentSize * n);
  M.resize(n);
  for (int i = 0; i < n; ++i) {
    const Pose xi = fromBlock(x[i]), li = fromBlock(x_lin_[i].data());
    dx.segment<6>(6 * i) = minus(xi, li);
    M[i] = minusJacobianAt(xi, li);
  }
  Eigen::VectorXd g0 = Jtr0_;
  g0.noalias() += JtJ_ * dx;
  g.resize(6 * n);
  for (int i = 0; i < n; ++i) g.segment<6>(6 * i).noalias() = M[i].transpose() * g0.segment<6>(6 * i);
  return half_r0_squared_ + 0.5 * dx.dot(Jtr0_ + g0);
}

Matrix6 MarginalizationPrior::hessianBlock(const std::vector<Matrix6>& M, int i, int j) const {
  // M_i = blockdiag(I, R_i) (minusJacobianAt): only the rotation rows and columns change.
  const Eigen::Matrix3d Ri = M[i].bottomRightCorner<3, 3>(), Rj = M[j].bottomRightCorner<3, 3>();
  const auto H = JtJ_.block<6, 6>(6 * i, 6 * j);
  Matrix6 out;
  out.topLeftCorner<3, 3>() = H.topLeftCorner<3, 3>();
  out.topRightCorner<3, 3>().noalias() = H.topRightCorner<3, 3>() * Rj;
  out.bottomLeftCorner<3, 3>().noalias() = Ri.transpose() * H.bottomLeftCorner<3, 3>();
  out.bottomRightCorner<3, 3>().noalias() = Ri.transpose() * H.bottomRightCorner<3, 3>() * Rj;
  return out;
}

void MarginalizationPrior::hessian(const std::vector<Matrix6>& M, Eigen::MatrixXd& H) const {
  const int n = numBlocks();
  H.resize(6 * n, 6 * n);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) H.block<6, 6>(6 * i, 6 * j) = hessianBlock(M, i, j);
}

void MarginalizationPrior::linearize(double const* const* x, Eigen::MatrixXd& H, Eigen::VectorXd& g) const {
  std::vector<Matrix6> M;
  gradient(x, M, g);
  hessian(M, H);
}

double MarginalizationPrior::curvature(const std::vector<Matrix6>& M, const Eigen::VectorXd& dx) const {
  Eigen::VectorXd Mdx(dx.size());
  for (int i = 0; i < numBlocks(); ++i) Mdx.segment<6>(6 * i).noalias() = M[i] * dx.segment<6>(6 * i);
  return Mdx.dot(JtJ_ * Mdx);
}

}  // namespace dlslot::backend
