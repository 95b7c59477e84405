#include "backend/factor_linearization.hpp"

#include <cmath>
#include <stdexcept>

#include "backend/marginalization_prior.hpp"
#include "backend/pose_factor.hpp"

namespace dlslot::backend {
namespace {

// Ceres' robust-loss correction (Triggs et al.): with s = |r|^2 and rho(s), the corrected
// residual and Jacobian give the same Gauss-Newton step as Ceres takes.
void applyLoss(const ceres::LossFunction& loss, FactorLinearization& lin) {
  const double s = lin.r.squaredNorm();
  double rho[3];
  loss.Evaluate(s, rho);
  lin.cost = 0.5 * rho[0];
  const double sqrt_rho1 = std::sqrt(std::max(rho[1], 0.0));
  if (s == 0.0 || rho[2] <= 0.0) {
    lin.r *= sqrt_rho1;
    for (auto& J : lin.J) J *= sqrt_rho1;
    return;
  }
  const double alpha = 1.0 - std::sqrt(1.0 + 2.0 * s * rho[2] / rho[1]);
  const Matrix6 P = Matrix6::Identity() - (alpha / s) * lin.r * lin.r.transpose();
  for (auto& J : lin.J) J = sqrt_rho1 * (P * J);
  lin.r *= sqrt_rho1 / (1.0 - alpha);
}

}  // namespace

void linearize(const Factor& f, const std::unordered_set<const double*>& fixed, FactorLinearization& lin) {
  const int nb = static_cast<int>(f.blocks.size());
  lin.estimated.resize(nb);
  for (int k = 0; k < nb; ++k) lin.estimated[k] = !fixed.count(f.blocks[k]);
  lin.prior = dynamic_cast<const MarginalizationPrior*>(f.cost.get());
  if (lin.prior) {
    lin.cost = lin.prior->gradient(f.blocks.data(), lin.M, lin.g);
    for (int k = 0; k < nb; ++k)
      if (!lin.estimated[k]) lin.g.segment<6>(6 * k).setZero();
    return;
  }
  const auto* factor = dynamic_cast<const PoseFactor*>(f.cost.get());
  if (!factor) throw std::logic_error("linearize: expected a PoseFactor or a MarginalizationPrior");
  lin.J.resize(nb);
  Matrix6* J[PoseFactor::kMaxBlocks] = {};
  for (int k = 0; k < nb; ++k) {
    if (lin.estimated[k]) {
      J[k] = &lin.J[k];
    } else {
      lin.J[k].setZero();  // a fixed block has no tangent
    }
  }
  lin.r = factor->evaluate(f.blocks.data(), J);
  lin.cost = 0.5 * lin.r.squaredNorm();
  if (f.loss) applyLoss(*f.loss, lin);
}

Vector6 FactorLinearization::gradientBlock(int a) const {
  if (prior) return g.segment<6>(6 * a);
  return J[a].transpose() * r;
}

Matrix6 FactorLinearization::hessianBlock(int a, int b) const {
  if (prior) return prior->hessianBlock(M, a, b);
  return J[a].transpose() * J[b];
}

double FactorLinearization::modelDecrease(const std::vector<Vector6>& dx) const {
  const int nb = static_cast<int>(estimated.size());
  if (prior) {
    Eigen::VectorXd d(6 * nb);
    for (int a = 0; a < nb; ++a) d.segment<6>(6 * a) = estimated[a] ? dx[a] : Vector6::Zero();
    return -(g.dot(d) + 0.5 * prior->curvature(M, d));
  }
  Vector6 Jdx = Vector6::Zero();
  for (int a = 0; a < nb; ++a)
    if (estimated[a]) Jdx.noalias() += J[a] * dx[a];
  return -(r.dot(Jdx) + 0.5 * Jdx.squaredNorm());
}

double factorCost(const Factor& f) {
  Vector6 small;
  Eigen::VectorXd large;
  double* r = small.data();
  if (f.cost->num_residuals() != 6) {
    large.resize(f.cost->num_residuals());
    r = large.data();
  }
  f.cost->Evaluate(f.blocks.data(), r, nullptr);
  const double s = Eigen::Map<const Eigen::VectorXd>(r, f.cost->num_residuals()).squaredNorm();
  if (!f.loss) return 0.5 * s;
  double rho[3];
  f.loss->Evaluate(s, rho);
  return 0.5 * rho[0];
}

}  // namespace dlslot::backend
