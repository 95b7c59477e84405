#include "backend/window_solver.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

#include "backend/pose_manifold.hpp"

namespace dlslot::backend {
namespace {

// Levenberg-Marquardt damping as Ceres applies it: H + mu diag(H), the diagonal clamped.
void damp(Eigen::MatrixXd& H, double mu) {
  for (Eigen::Index i = 0; i < H.rows(); ++i) H(i, i) += mu * std::clamp(H(i, i), 1e-6, 1e32);
}

// Half bandwidth of a symmetric matrix: the largest i - j with A(i, j) != 0.
int bandwidth(const Eigen::MatrixXd& A) {
  int bw = 0;
  for (Eigen::Index j = 0; j < A.cols(); ++j)
    for (Eigen::Index i = A.rows() - 1; i > j + bw; --i)
      if (A(i, j) != 0.0) {
        bw = static_cast<int>(i - j);
        break;
      }
  return bw;
}

}  // namespace

// A group is a chain in time (poses and pose changes of one object, interleaved), so its
// matrix is banded and so is its Cholesky factor: factor and substitute within the band.
bool WindowSolver::BandedCholesky::compute(const Eigen::MatrixXd& A) {
  L = A.triangularView<Eigen::Lower>();
  n = static_cast<int>(A.rows());
  bw = bandwidth(A);
  for (int j = 0; j < n; ++j) {
    const int m = std::min(bw, n - 1 - j);  // rows below the diagonal inside the band
    for (int k = std::max(0, j - bw); k < j; ++k) {
      const double ljk = L(j, k);
      const int rows = std::min(m + 1, k + bw + 1 - j);  // column k's band ends at row k + bw
      if (ljk != 0.0) L.col(j).segment(j, rows) -= ljk * L.col(k).segment(j, rows);
    }
    const double d = L(j, j);
    if (!(d > 0.0)) return false;
    L(j, j) = std::sqrt(d);
    L.col(j).segment(j + 1, m) /= L(j, j);
  }
  return true;
}

void WindowSolver::BandedCholesky::solveL(RowMatrix& B) const {
  for (int j = 0; j < n; ++j) {
    B.row(j) /= L(j, j);
    const int m = std::min(bw, n - 1 - j);
    if (m > 0) B.middleRows(j + 1, m).noalias() -= L.col(j).segment(j + 1, m) * B.row(j);
  }
}

void WindowSolver::BandedCholesky::solveLt(RowMatrix& B) const {
  for (int j = n - 1; j >= 0; --j) {
    const int m = std::min(bw, n - 1 - j);
    if (m > 0) B.row(j).noalias() -= L.col(j).segment(j + 1, m).transpose() * B.middleRows(j + 1, m);
    B.row(j) /= L(j, j);
  }
}

void WindowSolver::setUp(const std::vector<double*>& separator, const std::vector<std::vector<double*>>& groups,
                         const std::unordered_set<const double*>& fixed, int tail) {
  separator_.clear();
  groups_.clear();
  where_.clear();
  tail_dim_ = 0;
  tail_cov_.resize(0, 0);
  for (size_t i = 0; i < separator.size(); ++i) {
    if (fixed.count(separator[i])) continue;
    const int index = static_cast<int>(separator_.size());
    where_[separator[i]] = Location{-1, 6 * index, index};
    separator_.push_back(separator[i]);
    if (static_cast<int>(i) >= static_cast<int>(separator.size()) - tail) tail_dim_ += 6;
  }
  n_sep_ = 6 * static_cast<int>(separator_.size());
  for (const auto& blocks : groups) {
    Group g;
    for (double* b : blocks) {
      if (fixed.count(b)) continue;
      where_[b] = Location{static_cast<int>(groups_.size()), 6 * static_cast<int>(g.blocks.size()), 0};
      g.blocks.push_back(b);
    }
    g.n = 6 * static_cast<int>(g.blocks.size());
    if (g.n > 0) groups_.push_back(std::move(g));
  }
}

void WindowSolver::findCouplings(const std::vector<const Factor*>& factors) {
  std::vector<std::set<int>> touched(groups_.size());
  for (const Factor* f : factors) {
    int group = -1;
    for (double* b : f->blocks) {
      auto it = where_.find(b);
      if (it == where_.end() || it->second.group < 0) continue;
      if (group >= 0 && group != it->second.group) throw std::logic_error("WindowSolver: a factor touches two groups");
      group = it->second.group;
    }
    if (group < 0) continue;
    for (double* b : f->blocks) {
      auto it = where_.find(b);
      if (it != where_.end() && it->second.group < 0) touched[group].insert(it->second.index);
    }
  }
  for (size_t k = 0; k < groups_.size(); ++k) {
    Group& g = groups_[k];
    g.touched.assign(touched[k].begin(), touched[k].end());
    g.column.clear();
    for (size_t a = 0; a < g.touched.size(); ++a) g.column[g.touched[a]] = 6 * static_cast<int>(a);
  }
}

void WindowSolver::linearizeAll(const std::vector<const Factor*>& factors,
                                const std::unordered_set<const double*>& fixed) {
  H_sep_.setZero(n_sep_, n_sep_);
  g_sep_.setZero(n_sep_);
  for (Group& g : groups_) {
    g.H.setZero(g.n, g.n);
    g.g.setZero(g.n);
    g.C.setZero(g.n, 6 * static_cast<int>(g.touched.size()));
  }
  lin_.resize(factors.size());
  for (size_t i = 0; i < factors.size(); ++i) {
    const Factor& f = *factors[i];
    FactorLinearization& lin = lin_[i] = linearize(f, fixed);
    const int nb = static_cast<int>(f.blocks.size());
    std::vector<const Location*> loc(nb, nullptr);
    for (int a = 0; a < nb; ++a)
      if (!fixed.count(f.blocks[a])) loc[a] = &where_.at(f.blocks[a]);
    for (int a = 0; a < nb; ++a) {
      if (!loc[a]) continue;
      const Location& la = *loc[a];
      Group* group = la.group >= 0 ? &groups_[la.group] : nullptr;
      Eigen::VectorXd& g = group ? group->g : g_sep_;
      if (lin.is_prior) {
        g.segment<6>(la.offset) += lin.g.segment<6>(6 * a);
      } else {
        g.segment<6>(la.offset).noalias() += lin.J[a].transpose() * lin.r;
      }
      for (int b = 0; b < nb; ++b) {
        if (!loc[b]) continue;
        const Location& lb = *loc[b];
        Matrix6 block;
        if (lin.is_prior) {
          block = lin.H.block<6, 6>(6 * a, 6 * b);
        } else {
          block.noalias() = lin.J[a].transpose() * lin.J[b];
        }
        if (la.group < 0 && lb.group < 0) {
          H_sep_.block<6, 6>(la.offset, lb.offset) += block;
        } else if (la.group == lb.group) {
          group->H.block<6, 6>(la.offset, lb.offset) += block;
        } else if (lb.group < 0) {
          group->C.block<6, 6>(la.offset, group->column.at(lb.index)) += block;
        }  // (separator, group): the transpose of the case above
      }
    }
  }
  max_gradient_ = n_sep_ > 0 ? g_sep_.cwiseAbs().maxCoeff() : 0.0;
  for (const Group& g : groups_) max_gradient_ = std::max(max_gradient_, g.g.cwiseAbs().maxCoeff());
}

bool WindowSolver::solveStep(double mu, Eigen::VectorXd& step_sep, std::vector<Eigen::VectorXd>& step_groups) {
  Eigen::MatrixXd H = H_sep_;
  Eigen::VectorXd g = g_sep_;
  damp(H, mu);
  // Each group's Schur complement: with H_k = L L^T, Y = L^-1 C, z = L^-1 g_k, the separator
  // keeps H - Y^T Y and g - Y^T z.
  for (Group& grp : groups_) {
    Eigen::MatrixXd Hk = grp.H;
    damp(Hk, mu);
    if (!grp.chol.compute(Hk)) return false;
    // Y = L^-1 [C g].
    grp.Y.resize(grp.n, grp.C.cols() + 1);
    grp.Y << grp.C, grp.g;
    grp.chol.solveL(grp.Y);
    const int nc = static_cast<int>(grp.touched.size());
    Eigen::MatrixXd S = Eigen::MatrixXd::Zero(6 * nc, 6 * nc);
    S.selfadjointView<Eigen::Lower>().rankUpdate(grp.Y.leftCols(6 * nc).transpose());
    S = S.selfadjointView<Eigen::Lower>();
    const Eigen::VectorXd s = grp.Y.leftCols(6 * nc).transpose() * grp.Y.col(6 * nc);
    for (size_t a = 0; a < grp.touched.size(); ++a) {
      const int ra = 6 * grp.touched[a];
      g.segment<6>(ra) -= s.segment<6>(6 * a);
      for (size_t b = 0; b < grp.touched.size(); ++b)
        H.block<6, 6>(ra, 6 * grp.touched[b]) -= S.block<6, 6>(6 * a, 6 * b);
    }
  }
  step_sep.resize(n_sep_);
  if (n_sep_ > 0) {
    sep_llt_.compute(H);
    if (sep_llt_.info() != Eigen::Success) return false;
    step_sep = -sep_llt_.solve(g);
  }
  step_groups.resize(groups_.size());
  for (size_t k = 0; k < groups_.size(); ++k) {
    const Group& grp = groups_[k];
    Eigen::VectorXd d(6 * grp.touched.size());
    for (size_t a = 0; a < grp.touched.size(); ++a) d.segment<6>(6 * a) = step_sep.segment<6>(6 * grp.touched[a]);
    BandedCholesky::RowMatrix x = grp.Y.col(grp.Y.cols() - 1) + grp.Y.leftCols(grp.Y.cols() - 1) * d;
    grp.chol.solveLt(x);
    step_groups[k] = -x;
  }
  return true;
}

Eigen::VectorXd WindowSolver::stepOf(const double* block, const Eigen::VectorXd& step_sep,
                                     const std::vector<Eigen::VectorXd>& step_groups) const {
  auto it = where_.find(block);
  if (it == where_.end()) return Eigen::VectorXd::Zero(6);
  const Location& l = it->second;
  return l.group < 0 ? Eigen::VectorXd(step_sep.segment<6>(l.offset))
                     : Eigen::VectorXd(step_groups[l.group].segment<6>(l.offset));
}

double WindowSolver::modelCostChange(const std::vector<const Factor*>& factors, const Eigen::VectorXd& step_sep,
                                     const std::vector<Eigen::VectorXd>& step_groups) const {
  // cost - 0.5 |r + J dx|^2 summed over the factors (the linear model's predicted decrease).
  double change = 0;
  for (size_t i = 0; i < factors.size(); ++i) {
    const Factor& f = *factors[i];
    const FactorLinearization& lin = lin_[i];
    const int nb = static_cast<int>(f.blocks.size());
    if (lin.is_prior) {
      Eigen::VectorXd dx(6 * nb);
      for (int a = 0; a < nb; ++a) dx.segment<6>(6 * a) = stepOf(f.blocks[a], step_sep, step_groups);
      change -= lin.g.dot(dx) + 0.5 * dx.dot(lin.H * dx);
      continue;
    }
    Vector6 Jdx = Vector6::Zero();
    for (int a = 0; a < nb; ++a)
      if (lin.estimated[a]) Jdx += lin.J[a] * stepOf(f.blocks[a], step_sep, step_groups);
    change -= lin.r.dot(Jdx) + 0.5 * Jdx.squaredNorm();
  }
  return change;
}

WindowSolver::Summary WindowSolver::solve(const std::vector<const Factor*>& factors,
                                          const std::vector<double*>& separator,
                                          const std::vector<std::vector<double*>>& groups,
                                          const std::unordered_set<const double*>& fixed, int tail,
                                          const Options& options) {
  setUp(separator, groups, fixed, tail);
  findCouplings(factors);
  auto totalCost = [&] {
    double c = 0;
    for (const Factor* f : factors) c += factorCost(*f);
    return c;
  };
  Summary summary;
  double cost = summary.initial_cost = totalCost();
  summary.final_cost = cost;
  if (where_.empty()) return summary;

  std::vector<double*> estimated = separator_;
  for (const Group& g : groups_) estimated.insert(estimated.end(), g.blocks.begin(), g.blocks.end());
  std::vector<Vector7> saved(estimated.size());
  PoseManifold manifold;
  double radius = options.initial_trust_region_radius, decrease_factor = 2.0;
  Eigen::VectorXd step_sep;
  std::vector<Eigen::VectorXd> step_groups;
  double factored_mu = -1;  // damping of the last factorization, -1: none yet
  linearizeAll(factors, fixed);
  for (int it = 0; it < options.max_iterations; ++it) {
    if (max_gradient_ <= options.gradient_tolerance) break;
    ++summary.iterations;
    if (!solveStep(1.0 / radius, step_sep, step_groups)) {
      radius /= decrease_factor;
      decrease_factor *= 2;
      continue;
    }
    factored_mu = 1.0 / radius;
    double step_norm2 = step_sep.squaredNorm(), x_norm2 = 0;
    for (const auto& s : step_groups) step_norm2 += s.squaredNorm();
    for (size_t i = 0; i < estimated.size(); ++i) {
      saved[i] = Eigen::Map<const Vector7>(estimated[i]);
      x_norm2 += saved[i].squaredNorm();
    }
    if (std::sqrt(step_norm2) <= options.parameter_tolerance * (std::sqrt(x_norm2) + options.parameter_tolerance)) break;
    const double model_change = modelCostChange(factors, step_sep, step_groups);
    for (size_t i = 0; i < estimated.size(); ++i) {
      const Eigen::VectorXd d = stepOf(estimated[i], step_sep, step_groups);
      manifold.Plus(saved[i].data(), d.data(), estimated[i]);
    }
    const double new_cost = totalCost();
    const double rho = (cost - new_cost) / model_change;
    if (model_change > 0 && rho > 1e-3) {
      radius = radius / std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * rho - 1.0, 3));
      decrease_factor = 2.0;
      const bool converged = cost - new_cost <= options.function_tolerance * cost;
      cost = new_cost;
      if (converged || it + 1 == options.max_iterations) break;
      linearizeAll(factors, fixed);
    } else {
      for (size_t i = 0; i < estimated.size(); ++i) std::copy(saved[i].data(), saved[i].data() + 7, estimated[i]);
      radius /= decrease_factor;
      decrease_factor *= 2;
    }
  }
  summary.final_cost = cost;
  if (!options.covariance || tail_dim_ == 0) return summary;
  // Covariances want the undamped system: even mu = 1e-4 times the diagonal changes them by
  // percents along the window's weakly determined directions (a chain's diagonal is much larger
  // than its marginal information). Factor again when the last factorization was damped more
  // than rounding (the tiny mu only guards against it).
  if ((factored_mu < 0 || factored_mu > 1e-7) && !solveStep(1e-12, step_sep, step_groups)) return summary;
  const Eigen::MatrixXd L_tail = sep_llt_.matrixLLT().bottomRightCorner(tail_dim_, tail_dim_);
  Eigen::MatrixXd L_inv = Eigen::MatrixXd::Identity(tail_dim_, tail_dim_);
  L_tail.triangularView<Eigen::Lower>().solveInPlace(L_inv);
  tail_cov_ = L_inv.transpose() * L_inv;  // (L_tail L_tail^T)^-1: the trailing blocks' marginal
  return summary;
}

std::optional<Matrix6> WindowSolver::covariance(const double* block) const {
  auto it = where_.find(block);
  if (it == where_.end() || tail_cov_.size() == 0) return std::nullopt;
  const Location& l = it->second;
  const int tail_start = n_sep_ - tail_dim_;
  if (l.group < 0) {
    if (l.offset < tail_start) return std::nullopt;
    return Matrix6(tail_cov_.block<6, 6>(l.offset - tail_start, l.offset - tail_start));
  }
  // Group block: Sigma = [H_k^-1]_bb + W Sigma_tail W^T with W = [H_k^-1 C_k]_b over the
  // tail blocks the group touches.
  const Group& g = groups_[l.group];
  auto solve = [&g](BandedCholesky::RowMatrix B) {
    g.chol.solveL(B);
    g.chol.solveLt(B);
    return B;
  };
  BandedCholesky::RowMatrix E = BandedCholesky::RowMatrix::Zero(g.n, 6);
  E.middleRows<6>(l.offset).setIdentity();
  Matrix6 cov = solve(E).middleRows<6>(l.offset);
  std::vector<int> cols, tail_offsets;
  for (int s : g.touched)
    if (6 * s >= tail_start) {
      cols.push_back(g.column.at(s));
      tail_offsets.push_back(6 * s - tail_start);
    }
  if (cols.empty()) return cov;
  BandedCholesky::RowMatrix C(g.n, 6 * cols.size());
  Eigen::MatrixXd Sigma(6 * cols.size(), 6 * cols.size());
  for (size_t a = 0; a < cols.size(); ++a) {
    C.middleCols<6>(6 * a) = g.C.middleCols<6>(cols[a]);
    for (size_t b = 0; b < cols.size(); ++b)
      Sigma.block<6, 6>(6 * a, 6 * b) = tail_cov_.block<6, 6>(tail_offsets[a], tail_offsets[b]);
  }
  const Eigen::MatrixXd W = solve(C).middleRows<6>(l.offset);
  cov += W * Sigma * W.transpose();
  return cov;
}

}  // namespace dlslot::backend
