#include "backend/marginalizer.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "backend/dense_kernels.hpp"
#include "backend/factor_linearization.hpp"
#include "backend/se3.hpp"
#include "backend/marginalization_prior.hpp"

namespace dlslot::backend {
namespace {

// H* = H_rr - H_rm H_mm^-1 H_mr and g* = g_r - H_rm H_mm^-1 g_m for the first nm rows/columns
// leaving. With H_mm = L L^T and Y = L^-1 H_mr: H* = H_rr - Y^T Y and g* = g_r - Y^T L^-1 g_m.
// Kept block c's column of H_mr is zero above first_row[c] (non-decreasing), so is Y's: each
// group of columns is solved with the trailing part of L only, and Y^T Y is summed over bands
// of rows, each with the columns that are non-zero there. A singular H_mm (a direction no
// factor constrains, which carries no information to pass on) falls back to the pseudo-inverse.
void schurComplement(const Eigen::MatrixXd& H, const Eigen::VectorXd& g, int nm, std::vector<int> first_row,
                     Eigen::MatrixXd& H_star, Eigen::VectorXd& g_star) {
  const int nr = static_cast<int>(H.rows()) - nm;
  H_star = H.bottomRightCorner(nr, nr);
  g_star = g.tail(nr);
  Eigen::MatrixXd L = H.topLeftCorner(nm, nm);
  Eigen::MatrixXd Y = H.topRightCorner(nm, nr);
  Eigen::VectorXd z = g.head(nm);
  const int kept = nr / 6;
  if (dense::cholesky(L)) {
    for (int c0 = 0, c1 = 0; c0 < kept; c0 = c1) {
      const int p = first_row[c0];
      while (c1 < kept && first_row[c1] == p) ++c1;
      if (p < nm) dense::solveLower(L.bottomRightCorner(nm - p, nm - p), Y.block(p, 6 * c0, nm - p, 6 * (c1 - c0)));
    }
    dense::solveLower(L, z);
  } else {
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(H.topLeftCorner(nm, nm));
    const double eps = 1e-10 * std::max(1.0, es.eigenvalues().cwiseAbs().maxCoeff());
    const Eigen::VectorXd inv_sqrt =
        (es.eigenvalues().array() > eps).select(es.eigenvalues().cwiseMax(eps).cwiseSqrt().cwiseInverse(), 0.0);
    Y = inv_sqrt.asDiagonal() * (es.eigenvectors().transpose() * Y);
    z = inv_sqrt.asDiagonal() * (es.eigenvectors().transpose() * z);
    first_row.assign(kept, 0);  // Y is full now
  }
  // Rows [p, next p) are non-zero in the columns of the blocks with first_row <= p only.
  for (int c = 0; c < kept && first_row[c] < nm;) {
    const int p = first_row[c];
    while (c < kept && first_row[c] == p) ++c;
    const int end = c < kept ? std::min(first_row[c], nm) : nm;
    dense::subtractGram(Y.block(p, 0, end - p, 6 * c), H_star.topLeftCorner(6 * c, 6 * c));
  }
  H_star = H_star.selfadjointView<Eigen::Lower>();
  g_star.noalias() -= Y.transpose() * z;
}

// H = J^T J and g = J^T r  ->  (J, r); J is upper triangular when H is definite (returns
// true), else the eigen-decomposition without the null space (returns false).
bool factorize(const Eigen::MatrixXd& H, const Eigen::VectorXd& g, Eigen::MatrixXd& J, Eigen::VectorXd& r) {
  Eigen::MatrixXd L = H;
  if (dense::cholesky(L)) {
    J = L.triangularView<Eigen::Lower>().transpose();
    r = g;
    dense::solveLower(L, r);
    return true;
  }
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(H);
  const double eps = 1e-10 * std::max(1.0, es.eigenvalues().cwiseAbs().maxCoeff());
  const Eigen::ArrayXd lambda = (es.eigenvalues().array() > eps).select(es.eigenvalues().array(), 0.0);
  const Eigen::ArrayXd inv_sqrt = (lambda > 0).select(lambda.sqrt().inverse(), 0.0);
  J = lambda.sqrt().matrix().asDiagonal() * es.eigenvectors().transpose();
  r = inv_sqrt.matrix().asDiagonal() * (es.eigenvectors().transpose() * g);
  return false;
}

}  // namespace

std::optional<Factor> Marginalizer::marginalize(const std::vector<const Factor*>& factors,
                                                const std::unordered_set<const double*>& leaving,
                                                const std::unordered_set<const double*>& fixed) {
  stats_ = Stats();
  stats_.factors = static_cast<int>(factors.size());
  // Order the estimated blocks: leaving ones first, then the ones that stay, sorted by the
  // first leaving block they share a factor with (first_row; none: after all). A kept block is
  // coupled to few leaving ones (an object's next pose and change to its last ones), so its
  // columns of H_mr, and of L^-1 H_mr, are zero above that row: a staircase the Schur
  // complement exploits.
  std::vector<double*> order;
  std::unordered_map<const double*, int> index;
  for (const Factor* f : factors)
    for (double* b : f->blocks)
      if (!fixed.count(b) && leaving.count(b) && !index.count(b)) {
        index[b] = static_cast<int>(order.size());
        order.push_back(b);
      }
  const int n_leaving = static_cast<int>(order.size());
  std::unordered_map<double*, int> first_block;  // kept block -> first leaving block index
  std::vector<double*> kept;
  for (const Factor* f : factors) {
    int first = n_leaving;
    for (double* b : f->blocks)
      if (index.count(b)) first = std::min(first, index.at(b));
    for (double* b : f->blocks) {
      if (fixed.count(b) || leaving.count(b)) continue;
      auto [it, is_new] = first_block.emplace(b, first);
      if (is_new) kept.push_back(b);
      it->second = std::min(it->second, first);
    }
  }
  std::stable_sort(kept.begin(), kept.end(), [&](double* a, double* b) { return first_block[a] < first_block[b]; });
  std::vector<int> first_row;
  for (double* b : kept) {
    index[b] = static_cast<int>(order.size());
    order.push_back(b);
    first_row.push_back(6 * first_block[b]);
  }
  const int n = static_cast<int>(order.size());
  const int nm = 6 * (n - static_cast<int>(kept.size()));
  const int nr = 6 * static_cast<int>(kept.size());
  stats_.leaving_dim = nm;
  stats_.kept_dim = nr;
  if (nr == 0) return std::nullopt;

  // Linearize every factor at the current estimate into the dense H, g.
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(nm + nr, nm + nr);
  Eigen::VectorXd g = Eigen::VectorXd::Zero(nm + nr);
  FactorLinearization lin;
  Eigen::MatrixXd Hf;
  for (const Factor* f : factors) {
    const int nb = static_cast<int>(f->blocks.size());
    std::vector<int> at(nb);
    for (int k = 0; k < nb; ++k) at[k] = fixed.count(f->blocks[k]) ? -1 : 6 * index.at(f->blocks[k]);
    linearize(*f, fixed, lin);
    lin.hessian(Hf);
    for (int a = 0; a < nb; ++a) {
      if (at[a] < 0) continue;
      g.segment<6>(at[a]) += lin.gradientBlock(a);
      for (int b = 0; b < nb; ++b)
        if (at[b] >= 0) H.block<6, 6>(at[a], at[b]) += Hf.block<6, 6>(6 * a, 6 * b);
    }
  }

  // Schur complement onto the kept blocks.
  Eigen::MatrixXd H_star = H.bottomRightCorner(nr, nr);
  Eigen::VectorXd g_star = g.tail(nr);
  if (nm > 0) schurComplement(H, g, nm, first_row, H_star, g_star);

  // A kept block the eliminated factors say nothing about (e.g. the second pose of an object
  // whose first one leaves: the pose change used up what its observation said) gets no prior.
  std::vector<int> informed;
  for (int k = 0; k < static_cast<int>(kept.size()); ++k)
    if (H_star.block<6, 6>(6 * k, 6 * k).norm() > 1e-12 * std::max(1.0, H_star.diagonal().cwiseAbs().maxCoeff()))
      informed.push_back(k);
  if (informed.empty()) return std::nullopt;
  if (informed.size() < kept.size()) {
    std::vector<int> idx;
    for (int k : informed)
      for (int d = 0; d < 6; ++d) idx.push_back(6 * k + d);
    const Eigen::MatrixXd H_full = H_star;
    const Eigen::VectorXd g_full = g_star;
    H_star = H_full(idx, idx);
    g_star = g_full(idx);
    std::vector<double*> still;
    for (int k : informed) still.push_back(kept[k]);
    kept = still;
    stats_.kept_dim = 6 * static_cast<int>(kept.size());
  }

  Eigen::MatrixXd J_star;
  Eigen::VectorXd r_star;
  if (!factorize(H_star, g_star, J_star, r_star)) {
    H_star.resize(0, 0);  // recomputed from J* (the null space was left out)
    g_star.resize(0);
  }
  std::vector<Vector7> x_lin;
  x_lin.reserve(kept.size());
  for (double* b : kept) x_lin.push_back(Eigen::Map<const Vector7>(b));
  Factor prior;
  prior.cost = std::make_shared<MarginalizationPrior>(std::move(x_lin), std::move(J_star), std::move(r_star),
                                                     std::move(H_star), std::move(g_star));
  prior.blocks = kept;
  return prior;
}

}  // namespace dlslot::backend
