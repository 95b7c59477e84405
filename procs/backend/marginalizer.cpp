#include "backend/marginalizer.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "backend/dense_kernels.hpp"
#include "backend/factor_linearization.hpp"
#include "backend/se3.hpp"
#include "backend/marginalization_prior.hpp"
#include "backend/parallel_for.hpp"

namespace dlslot::backend {
namespace {

// Kept blocks per panel of the Schur complement's solves and products: wide enough for the
// dense kernels to run near their peak, narrow enough that few zeros above the staircase are
// worked on and that two threads have several panels to share.
constexpr int kPanelBlocks = 4;

// H* = H_rr - H_rm H_mm^-1 H_mr and g* = g_r - H_rm H_mm^-1 g_m, in place: on entry H_mm,
// H_mr, H_rr (lower triangle) and g_m, g_r; on exit H_rr holds H* and g_r holds g*, the others
// are used up. With H_mm = L L^T and Y = L^-1 H_mr: H* = H_rr - Y^T Y, g* = g_r - Y^T L^-1 g_m.
// Kept block c's column of H_mr is zero above first_row[c] (non-decreasing), so is Y's. The
// kept blocks are taken in panels: a panel's columns of Y are solved with L's trailing part
// from its first row p only, and its rows of Y^T Y summed over Y's rows from p only (the
// panels in parallel). A singular H_mm (a direction no factor constrains, which carries
// no information to pass on) falls back to the pseudo-inverse.
void schurComplement(Eigen::MatrixXd& H_mm, Eigen::MatrixXd& H_mr, Eigen::MatrixXd& H_rr, Eigen::VectorXd& g_m,
                     Eigen::VectorXd& g_r, std::vector<int> first_row, ParallelFor* parallel) {
  const int nm = static_cast<int>(H_mm.rows()), kept = static_cast<int>(H_rr.rows()) / 6;
  Eigen::MatrixXd& L = H_mm;
  Eigen::MatrixXd& Y = H_mr;
  const Eigen::VectorXd diagonal = H_mm.diagonal();
  const bool definite = dense::cholesky(L);
  if (!definite) {
    // The Cholesky left the upper triangle alone: H_mm is still there, but for its diagonal.
    // (The eigen solver reads the lower triangle.)
    Eigen::MatrixXd H = H_mm.transpose();
    H.diagonal() = diagonal;
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(H);
    const double eps = 1e-10 * std::max(1.0, es.eigenvalues().cwiseAbs().maxCoeff());
    const Eigen::VectorXd inv_sqrt =
        (es.eigenvalues().array() > eps).select(es.eigenvalues().cwiseMax(eps).cwiseSqrt().cwiseInverse(), 0.0);
    Y = inv_sqrt.asDiagonal() * (es.eigenvectors().transpose() * Y);
    g_m = inv_sqrt.asDiagonal() * (es.eigenvectors().transpose() * g_m);
    first_row.assign(kept, 0);  // Y is full now
  }
  // Panels of kept blocks [c0, c1): rows from first_row[c0] on hold all their non-zeros.
  std::vector<std::pair<int, int>> panels;
  for (int c0 = 0; c0 < kept && first_row[c0] < nm; c0 += kPanelBlocks) {
    int c1 = std::min(c0 + kPanelBlocks, kept);
    while (first_row[c1 - 1] >= nm) --c1;
    panels.emplace_back(c0, c1);
  }
  const int n_panels = static_cast<int>(panels.size());
  if (definite) {
    parallelFor(parallel, n_panels, [&](int k) {
      const auto [c0, c1] = panels[k];
      const int p = first_row[c0];
      dense::solveLower(L.bottomRightCorner(nm - p, nm - p), Y.block(p, 6 * c0, nm - p, 6 * (c1 - c0)));
    });
    dense::solveLower(L, g_m);
  }
  // The panel's rows of Y^T Y up to its last column (those right of the diagonal are not used:
  // H_rr's lower triangle is what counts).
  parallelFor(parallel, n_panels, [&](int k) {
    const auto [c0, c1] = panels[k];
    const int p = first_row[c0];
    dense::subtractProductTN(Y.block(p, 6 * c0, nm - p, 6 * (c1 - c0)), Y.block(p, 0, nm - p, 6 * c1),
                             H_rr.block(6 * c0, 0, 6 * (c1 - c0), 6 * c1));
  });
  g_r.noalias() -= Y.transpose() * g_m;
}

// H = J^T J and g = J^T r  ->  (J, r); J is upper triangular when H is definite (returns
// true), else the eigen-decomposition without the null space (returns false). The Cholesky
// factor L is formed in J's own storage: row-major J = L^T is column-major L.
bool factorize(const Eigen::MatrixXd& H, const Eigen::VectorXd& g, dense::RowMatrix& J,
               Eigen::VectorXd& r) {
  J = Eigen::Map<const dense::RowMatrix>(H.data(), H.rows(), H.cols());  // H^T = H, a plain copy
  Eigen::Map<Eigen::MatrixXd> L(J.data(), J.rows(), J.cols());
  if (dense::cholesky(L)) {
    L.triangularView<Eigen::StrictlyUpper>().setZero();
    r = g;
    dense::solveLower(L, r);
    return true;
  }
  // Directions no factor informs at all (exactly zero rows and columns: the rotation of a pose
  // change that only a constant-acceleration factor, which measures translations, ties to the
  // leaving blocks) carry no information: the rest is factorized without them, and J has zero
  // columns there. Only a rest that is still singular needs the eigen-decomposition.
  std::vector<Eigen::Index> informed;
  for (Eigen::Index i = 0; i < H.rows(); ++i)
    if (H.row(i).cwiseAbs().maxCoeff() > 0.0) informed.push_back(i);
  if (!informed.empty() && static_cast<Eigen::Index>(informed.size()) < H.rows()) {
    const Eigen::Index m = static_cast<Eigen::Index>(informed.size());
    Eigen::MatrixXd Lr = H(informed, informed);
    if (dense::cholesky(Lr)) {
      Lr.triangularView<Eigen::StrictlyUpper>().setZero();
      Eigen::VectorXd gr = g(informed);
      dense::solveLower(Lr, gr);
      J = dense::RowMatrix::Zero(m, H.cols());
      for (Eigen::Index k = 0; k < m; ++k) J.col(informed[k]) = Lr.row(k).transpose();  // J = L^T
      r = gr;
      return true;
    }
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

  // Linearize every factor at the current estimate (in parallel), then sum into the blocks
  // H_mm, H_mr, H_rr (lower triangle) and g_m, g_r of the dense H, g.
  std::vector<FactorLinearization> lin(factors.size());
  const int nf = static_cast<int>(factors.size());
  parallelFor(parallel_, nf, [&](int i) { linearize(*factors[i], fixed, lin[i]); });
  Eigen::MatrixXd H_mm = Eigen::MatrixXd::Zero(nm, nm), H_mr = Eigen::MatrixXd::Zero(nm, nr);
  Eigen::MatrixXd H_star = Eigen::MatrixXd::Zero(nr, nr);
  Eigen::VectorXd g_m = Eigen::VectorXd::Zero(nm), g_star = Eigen::VectorXd::Zero(nr);
  for (int i = 0; i < nf; ++i) {
    const Factor* f = factors[i];
    const int nb = static_cast<int>(f->blocks.size());
    std::vector<int> at(nb);
    for (int k = 0; k < nb; ++k) at[k] = fixed.count(f->blocks[k]) ? -1 : 6 * index.at(f->blocks[k]);
    for (int a = 0; a < nb; ++a) {
      if (at[a] < 0) continue;
      (at[a] < nm ? g_m.segment<6>(at[a]) : g_star.segment<6>(at[a] - nm)) += lin[i].gradientBlock(a);
      for (int b = 0; b < nb; ++b) {
        if (at[b] < 0) continue;
        if (at[a] < nm && at[b] < nm) {
          H_mm.block<6, 6>(at[a], at[b]) += lin[i].hessianBlock(a, b);
        } else if (at[a] < nm) {
          H_mr.block<6, 6>(at[a], at[b] - nm) += lin[i].hessianBlock(a, b);
        } else if (at[b] >= nm && at[b] <= at[a]) {
          H_star.block<6, 6>(at[a] - nm, at[b] - nm) += lin[i].hessianBlock(a, b);
        }  // (kept, leaving): the transpose of H_mr; H_rr keeps its lower triangle
      }
    }
  }

  // Schur complement onto the kept blocks.
  if (nm > 0) schurComplement(H_mm, H_mr, H_star, g_m, g_star, first_row, parallel_);
  H_star = H_star.selfadjointView<Eigen::Lower>();

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

  dense::RowMatrix J_star;
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
