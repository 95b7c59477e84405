#include "backend/window_solver.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

#include "backend/dense_kernels.hpp"
#include "backend/pose_manifold.hpp"

namespace dlslot::backend {
namespace {

// Levenberg-Marquardt damping as Ceres applies it: H + mu diag(H), the diagonal clamped.
double damping(double diagonal, double mu) { return mu * std::clamp(diagonal, 1e-6, 1e32); }

}  // namespace

bool WindowSolver::BandCholesky::compute(const std::vector<Matrix6>& H, int blocks, int bandwidth, double mu) {
  m = blocks;
  w = bandwidth;
  Eigen::VectorXd added(6 * m);
  for (int i = 0; i < m; ++i)
    for (int r = 0; r < 6; ++r) added(6 * i + r) = damping(H[i * (w + 1)](r, r), mu);
  return dense::bandCholesky(H, m, w, added, L, L_inv);
}

void WindowSolver::BandCholesky::solveL(RowMatrix& B, const std::vector<int>* widths) const {
  dense::bandSolveLower(L, L_inv, w, B, widths);
}

void WindowSolver::BandCholesky::solveLt(RowMatrix& B) const { dense::bandSolveLowerTransposed(L, L_inv, w, B); }

void WindowSolver::setUp(const std::vector<double*>& separator, const std::vector<std::vector<double*>>& groups,
                         const std::unordered_set<const double*>& fixed, int tail) {
  separator_.clear();
  where_.clear();
  tail_dim_ = 0;
  tail_cov_.resize(0, 0);
  for (size_t i = 0; i < separator.size(); ++i) {
    if (fixed.count(separator[i])) continue;
    where_[separator[i]] = Slot{-1, static_cast<int>(separator_.size())};
    separator_.push_back(separator[i]);
    if (static_cast<int>(i) >= static_cast<int>(separator.size()) - tail) tail_dim_ += 6;
  }
  n_sep_ = 6 * static_cast<int>(separator_.size());
  // The groups' matrices keep their storage from the last solve (the window changes little
  // from frame to frame, so their sizes mostly stay): no reallocation, and warm caches.
  int k = 0;
  for (const auto& blocks : groups) {
    if (k == static_cast<int>(groups_.size())) groups_.emplace_back();
    Group& g = groups_[k];
    g.blocks.clear();
    g.factors.clear();
    g.w = 0;
    for (double* b : blocks) {
      if (fixed.count(b)) continue;
      where_[b] = Slot{k, static_cast<int>(g.blocks.size())};
      g.blocks.push_back(b);
    }
    g.m = static_cast<int>(g.blocks.size());
    if (g.m > 0) ++k;
  }
  groups_.resize(k);
}

void WindowSolver::mapFactors(const std::vector<const Factor*>& factors) {
  std::vector<std::set<int>> touched(groups_.size());
  std::vector<int> factor_group(factors.size(), -1);
  separator_factors_.clear();
  slots_.resize(factors.size());
  for (size_t i = 0; i < factors.size(); ++i) {
    const Factor& f = *factors[i];
    std::vector<Slot>& slots = slots_[i];
    slots.assign(f.blocks.size(), Slot{});
    int group = -1;
    for (size_t a = 0; a < f.blocks.size(); ++a) {
      auto it = where_.find(f.blocks[a]);
      if (it == where_.end()) continue;
      slots[a] = it->second;
      if (it->second.group < 0) continue;
      if (group >= 0 && group != it->second.group) throw std::logic_error("WindowSolver: a factor touches two groups");
      group = it->second.group;
    }
    factor_group[i] = group;
    if (group < 0) {
      separator_factors_.push_back(static_cast<int>(i));
      continue;
    }
    Group& g = groups_[group];
    g.factors.push_back(static_cast<int>(i));
    for (const Slot& a : slots) {
      if (a.group == -1) touched[group].insert(a.index);
      for (const Slot& b : slots)
        if (a.group == group && b.group == group) g.w = std::max(g.w, std::abs(a.index - b.index));
    }
  }
  // Columns of C: the touched separator blocks in separator order.
  std::vector<std::unordered_map<int, int>> column(groups_.size());
  for (size_t k = 0; k < groups_.size(); ++k) {
    Group& g = groups_[k];
    g.touched.assign(touched[k].begin(), touched[k].end());
    for (size_t a = 0; a < g.touched.size(); ++a) column[k][g.touched[a]] = 6 * static_cast<int>(a);
  }
  // Each column's first non-zero block row, then the staircase's widths.
  std::vector<std::vector<int>> first(groups_.size());
  for (size_t k = 0; k < groups_.size(); ++k) first[k].assign(groups_[k].touched.size(), groups_[k].m);
  for (size_t i = 0; i < factors.size(); ++i) {
    const int k = factor_group[i];
    if (k < 0) continue;
    int row = groups_[k].m;
    for (const Slot& s : slots_[i])
      if (s.group == k) row = std::min(row, s.index);
    for (Slot& s : slots_[i]) {
      if (s.group != -1) continue;
      s.column = column[k].at(s.index);
      first[k][s.column / 6] = std::min(first[k][s.column / 6], row);
    }
  }
  for (size_t k = 0; k < groups_.size(); ++k) {
    Group& g = groups_[k];
    g.widths.assign(g.m, 0);
    for (size_t a = 0; a < g.touched.size(); ++a)
      for (int row = first[k][a]; row < g.m; ++row) g.widths[row] = std::max(g.widths[row], 6 * static_cast<int>(a) + 6);
  }
}

void WindowSolver::forEachItem(const std::function<void(int)>& work) {
  parallelFor(parallel_, static_cast<int>(groups_.size()) + 1, work);
}

double WindowSolver::sumOverItems(const std::function<double(int)>& work) {
  item_sums_.assign(groups_.size() + 1, 0.0);
  forEachItem([&](int item) { item_sums_[item] = work(item); });
  double sum = 0;
  for (double s : item_sums_) sum += s;
  return sum;
}

double WindowSolver::linearizeAll(const std::vector<const Factor*>& factors,
                                  const std::unordered_set<const double*>& fixed) {
  ++linearizations_;
  lin_.resize(factors.size());
  const double cost = sumOverItems([&](int item) {
    double item_cost = 0;
    if (item == 0) {
      g_sep_.setZero(n_sep_);
      H_sep_.resize(n_sep_, n_sep_);
      H_sep_.triangularView<Eigen::Lower>().setZero();
    } else {
      Group& g = groups_[item - 1];
      const int nc = 6 * static_cast<int>(g.touched.size());
      g.g.setZero(6 * g.m);
      g.g_touched.setZero(nc);
      g.H.assign(g.m * (g.w + 1), Matrix6::Zero());
      g.Y.setZero(6 * g.m, nc);
      g.S.setZero(nc, nc);
    }
    for (int i : itemFactors(item)) {
      FactorLinearization& lin = lin_[i];
      linearize(*factors[i], fixed, lin);
      item_cost += lin.cost;
      // The Hessian's 6x6 blocks are formed only where they are kept (the band and the
      // separator keep lower halves).
      const std::vector<Slot>& slots = slots_[i];
      const int nb = static_cast<int>(slots.size());
      for (int a = 0; a < nb; ++a) {
        const Slot& sa = slots[a];
        if (sa.group == -2) continue;
        if (item == 0) {
          g_sep_.segment<6>(6 * sa.index) += lin.gradientBlock(a);
          for (int b = 0; b < nb; ++b) {
            const int ib = slots[b].index;
            if (slots[b].group != -1 || ib > sa.index) continue;
            auto target = H_sep_.block<6, 6>(6 * sa.index, 6 * ib);
            if (ib < sa.index) {
              target += lin.hessianBlock(a, b);
            } else {
              target.triangularView<Eigen::Lower>() += lin.hessianBlock(a, b);
            }
          }
          continue;
        }
        Group& g = groups_[item - 1];
        if (sa.group >= 0) {
          g.g.segment<6>(6 * sa.index) += lin.gradientBlock(a);
        } else {
          g.g_touched.segment<6>(sa.column) += lin.gradientBlock(a);
        }
        for (int b = 0; b < nb; ++b) {
          const Slot& sb = slots[b];
          if (sb.group == -2) continue;
          if (sa.group >= 0 && sb.group >= 0) {
            if (sb.index <= sa.index) g.H[sa.index * (g.w + 1) + (sa.index - sb.index)] += lin.hessianBlock(a, b);
          } else if (sa.group >= 0) {
            g.Y.block<6, 6>(6 * sa.index, sb.column) += lin.hessianBlock(a, b);
          } else if (sb.group == -1 && sb.column <= sa.column) {
            g.S.block<6, 6>(sa.column, sb.column) += lin.hessianBlock(a, b);
          }  // (separator, group): the transpose of C; the band and D keep lower halves
        }
      }
    }
    return item_cost;
  });
  diag_sep_ = H_sep_.diagonal();
  for (const Group& g : groups_)
    for (size_t a = 0; a < g.touched.size(); ++a) {
      g_sep_.segment<6>(6 * g.touched[a]) += g.g_touched.segment<6>(6 * a);
      diag_sep_.segment<6>(6 * g.touched[a]) += g.S.diagonal().segment<6>(6 * a);
    }
  max_gradient_ = n_sep_ > 0 ? g_sep_.cwiseAbs().maxCoeff() : 0.0;
  for (const Group& g : groups_) max_gradient_ = std::max(max_gradient_, g.g.cwiseAbs().maxCoeff());
  return cost;
}

double WindowSolver::totalCost(const std::vector<const Factor*>& factors) {
  return sumOverItems([&](int item) {
    double cost = 0;
    for (int i : itemFactors(item)) cost += factorCost(*factors[i]);
    return cost;
  });
}

bool WindowSolver::factor(double mu) {
  // Each group's Schur complement: with H_k = L L^T and Y = L^-1 C, the separator keeps
  // D - Y^T Y over the blocks the group touches.
  factored_linearization_ = -1;  // until it succeeds
  std::vector<char> ok(groups_.size());
  forEachItem([&](int item) {
    if (item == 0) {
      // The separator's own part, damped, while the groups are being eliminated.
      H_reduced_.resize(n_sep_, n_sep_);
      H_reduced_.triangularView<Eigen::Lower>() = H_sep_;
      for (int i = 0; i < n_sep_; ++i) H_reduced_(i, i) += damping(diag_sep_(i), mu);
      return;
    }
    Group& grp = groups_[item - 1];
    ok[item - 1] = grp.chol.compute(grp.H, grp.m, grp.w, mu);
    if (!ok[item - 1]) return;
    grp.chol.solveL(grp.Y, &grp.widths);
    dense::subtractGramRows(grp.Y, grp.S);
  });
  if (std::find(ok.begin(), ok.end(), 0) != ok.end()) return false;
  factored_linearization_ = linearizations_;
  // Lower triangles only (the upper one is not even initialized): touched is in separator
  // order, so S's lower blocks land in H_reduced_'s lower triangle, all the Cholesky reads.
  for (const Group& grp : groups_)
    for (size_t a = 0; a < grp.touched.size(); ++a) {
      for (size_t b = 0; b < a; ++b)
        H_reduced_.block<6, 6>(6 * grp.touched[a], 6 * grp.touched[b]) += grp.S.block<6, 6>(6 * a, 6 * b);
      H_reduced_.block<6, 6>(6 * grp.touched[a], 6 * grp.touched[a]).triangularView<Eigen::Lower>() +=
          grp.S.block<6, 6>(6 * a, 6 * a);
    }
  return n_sep_ == 0 || dense::cholesky(H_reduced_);
}

void WindowSolver::substitute() {
  // The separator's gradient after the groups' elimination: g - Y^T z with z = L^-1 g_k.
  forEachItem([&](int item) {
    if (item == 0) return;
    Group& grp = groups_[item - 1];
    grp.z = grp.g;
    grp.chol.solveL(grp.z);
    grp.Ytz.noalias() = grp.Y.transpose() * grp.z;
  });
  Eigen::VectorXd g = g_sep_;
  for (const Group& grp : groups_)
    for (size_t a = 0; a < grp.touched.size(); ++a) g.segment<6>(6 * grp.touched[a]) -= grp.Ytz.segment<6>(6 * a);
  if (n_sep_ > 0) {
    dense::solveLower(H_reduced_, g);
    dense::solveLowerTransposed(H_reduced_, g);
  }
  step_sep_ = -g;
  // Back-substitution: x_k = -H_k^-1 (g_k + C d) = -L^-T (z + Y d), d the separator's step.
  step_groups_.resize(groups_.size());
  forEachItem([&](int item) {
    if (item == 0) return;
    Group& grp = groups_[item - 1];
    Eigen::VectorXd d(grp.Y.cols());
    for (size_t a = 0; a < grp.touched.size(); ++a) d.segment<6>(6 * a) = step_sep_.segment<6>(6 * grp.touched[a]);
    grp.z.noalias() += grp.Y * d;
    grp.chol.solveLt(grp.z);
    step_groups_[item - 1] = -grp.z;
  });
}

Vector6 WindowSolver::stepOf(const Slot& s) const {
  if (s.group == -2) return Vector6::Zero();
  return s.group < 0 ? Vector6(step_sep_.segment<6>(6 * s.index)) : Vector6(step_groups_[s.group].segment<6>(6 * s.index));
}

double WindowSolver::modelCostChange() {
  // cost - 0.5 |r + J dx|^2 summed over the factors (the linear model's predicted decrease).
  return sumOverItems([&](int item) {
    double change = 0;
    std::vector<Vector6> dx;
    for (int i : itemFactors(item)) {
      dx.clear();
      for (const Slot& s : slots_[i]) dx.push_back(stepOf(s));
      change += lin_[i].modelDecrease(dx);
    }
    return change;
  });
}

WindowSolver::Summary WindowSolver::solve(const std::vector<const Factor*>& factors,
                                          const std::vector<double*>& separator,
                                          const std::vector<std::vector<double*>>& groups,
                                          const std::unordered_set<const double*>& fixed, int tail,
                                          const Options& options, ParallelFor* parallel) {
  parallel_ = parallel && parallel->threads() > 1 ? parallel : nullptr;
  setUp(separator, groups, fixed, tail);
  mapFactors(factors);
  Summary summary;
  if (where_.empty()) {
    summary.initial_cost = summary.final_cost = totalCost(factors);
    return summary;
  }

  // Every estimated block with its step's slot, for applying and undoing steps.
  std::vector<std::pair<double*, Slot>> estimated;
  for (double* b : separator_) estimated.emplace_back(b, where_.at(b));
  for (const Group& g : groups_)
    for (double* b : g.blocks) estimated.emplace_back(b, where_.at(b));
  std::vector<Vector7> saved(estimated.size());
  PoseManifold manifold;
  double radius = options.initial_trust_region_radius, decrease_factor = 2.0;
  double factored_mu = -1;  // damping of the last factorization, -1: none yet
  double cost = summary.initial_cost = summary.final_cost = linearizeAll(factors, fixed);
  for (int it = 0; it < options.max_iterations; ++it) {
    if (max_gradient_ <= options.gradient_tolerance) break;
    ++summary.iterations;
    if (!factor(1.0 / radius)) {
      radius /= decrease_factor;
      decrease_factor *= 2;
      linearizeAll(factors, fixed);  // the failed factorization used it up
      continue;
    }
    factored_mu = 1.0 / radius;
    substitute();
    double step_norm2 = step_sep_.squaredNorm(), x_norm2 = 0;
    for (const auto& s : step_groups_) step_norm2 += s.squaredNorm();
    for (size_t i = 0; i < estimated.size(); ++i) {
      saved[i] = Eigen::Map<const Vector7>(estimated[i].first);
      x_norm2 += saved[i].squaredNorm();
    }
    if (std::sqrt(step_norm2) <= options.parameter_tolerance * (std::sqrt(x_norm2) + options.parameter_tolerance)) break;
    const double model_change = modelCostChange();
    for (size_t i = 0; i < estimated.size(); ++i) {
      const Vector6 d = stepOf(estimated[i].second);
      manifold.Plus(saved[i].data(), d.data(), estimated[i].first);
    }
    // The new point's cost: from linearizing there when another step may follow (which an
    // accepted step needs anyway), else from the residuals alone.
    const bool last = it + 1 == options.max_iterations;
    const double new_cost = last ? totalCost(factors) : linearizeAll(factors, fixed);
    const double rho = (cost - new_cost) / model_change;
    if (model_change > 0 && rho > 1e-3) {
      radius = radius / std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * rho - 1.0, 3));
      decrease_factor = 2.0;
      const bool converged = cost - new_cost <= options.function_tolerance * cost;
      cost = new_cost;
      if (converged || last) break;
    } else {
      for (size_t i = 0; i < estimated.size(); ++i)
        std::copy(saved[i].data(), saved[i].data() + 7, estimated[i].first);
      radius /= decrease_factor;
      decrease_factor *= 2;
      if (!last) linearizeAll(factors, fixed);  // back at the kept point
    }
  }
  summary.final_cost = cost;
  if (!options.covariance || tail_dim_ == 0) return summary;
  // Covariances want the undamped system: even mu = 1e-4 times the diagonal changes them by
  // percents along the window's weakly determined directions (a chain's diagonal is much larger
  // than its marginal information). Factor again (at the solution) when the last factorization
  // was damped more than rounding (the tiny mu only guards against it), or the groups' matrices
  // were linearized again since.
  if (factored_mu < 0 || factored_mu > 1e-7 || factored_linearization_ != linearizations_) {
    linearizeAll(factors, fixed);
    if (!factor(1e-12)) return summary;
  }
  const Eigen::MatrixXd L_tail = H_reduced_.bottomRightCorner(tail_dim_, tail_dim_);
  Eigen::MatrixXd L_inv = Eigen::MatrixXd::Identity(tail_dim_, tail_dim_);
  L_tail.triangularView<Eigen::Lower>().solveInPlace(L_inv);
  tail_cov_ = L_inv.transpose() * L_inv;  // (L_tail L_tail^T)^-1: the trailing blocks' marginal
  return summary;
}

std::optional<Matrix6> WindowSolver::covariance(const double* block) const {
  const std::optional<Eigen::MatrixXd> cov = jointCovariance({block});
  if (!cov) return std::nullopt;
  return Matrix6(*cov);
}

std::optional<Eigen::MatrixXd> WindowSolver::jointCovariance(const std::vector<const double*>& blocks) const {
  if (tail_cov_.size() == 0 || blocks.empty()) return std::nullopt;
  std::vector<const Slot*> slots;
  for (const double* block : blocks) {
    auto it = where_.find(block);
    if (it == where_.end() || it->second.group != where_.at(blocks.front()).group) return std::nullopt;
    slots.push_back(&it->second);
  }
  const int n = static_cast<int>(blocks.size());
  const int tail_start = n_sep_ - tail_dim_;
  Eigen::MatrixXd cov(6 * n, 6 * n);
  if (slots.front()->group < 0) {
    for (int a = 0; a < n; ++a)
      if (slots[a]->group == -2 || 6 * slots[a]->index < tail_start) return std::nullopt;
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b)
        cov.block<6, 6>(6 * a, 6 * b) =
            tail_cov_.block<6, 6>(6 * slots[a]->index - tail_start, 6 * slots[b]->index - tail_start);
    return cov;
  }
  // Group blocks: Sigma = [H_k^-1]_ab + W_a Sigma_tail W_b^T with W = [H_k^-1 C_k] over the tail
  // blocks the group touches.
  const Group& g = groups_[slots.front()->group];
  RowMatrix E = RowMatrix::Zero(6 * g.m, 6 * n);
  for (int a = 0; a < n; ++a) E.block<6, 6>(6 * slots[a]->index, 6 * a).setIdentity();
  g.chol.solveL(E);
  g.chol.solveLt(E);  // the columns of H_k^-1
  for (int a = 0; a < n; ++a) cov.middleRows<6>(6 * a) = E.middleRows<6>(6 * slots[a]->index);
  std::vector<int> cols, tail_offsets;
  for (size_t a = 0; a < g.touched.size(); ++a)
    if (6 * g.touched[a] >= tail_start) {
      cols.push_back(6 * static_cast<int>(a));
      tail_offsets.push_back(6 * g.touched[a] - tail_start);
    }
  if (cols.empty()) return cov;
  RowMatrix W(6 * g.m, 6 * cols.size());  // H_k^-1 C = L^-T Y over the tail columns
  Eigen::MatrixXd Sigma(6 * cols.size(), 6 * cols.size());
  for (size_t a = 0; a < cols.size(); ++a) {
    W.middleCols<6>(6 * a) = g.Y.middleCols<6>(cols[a]);
    for (size_t b = 0; b < cols.size(); ++b)
      Sigma.block<6, 6>(6 * a, 6 * b) = tail_cov_.block<6, 6>(tail_offsets[a], tail_offsets[b]);
  }
  g.chol.solveLt(W);
  Eigen::MatrixXd W_blocks(6 * n, W.cols());
  for (int a = 0; a < n; ++a) W_blocks.middleRows<6>(6 * a) = W.middleRows<6>(6 * slots[a]->index);
  cov += W_blocks * Sigma * W_blocks.transpose();
  return cov;
}

}  // namespace dlslot::backend
