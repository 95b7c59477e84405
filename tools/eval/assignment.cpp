#include "assignment.hpp"

#include <cmath>
#include <limits>

namespace dlslot::eval {
namespace {

// Shortest augmenting paths with row/column potentials (Kuhn-Munkres, O(n^2 m)), for n <= m.
std::vector<int> assignRowsToCols(const Eigen::MatrixXd& a) {
  const int n = static_cast<int>(a.rows()), m = static_cast<int>(a.cols());
  const double inf = std::numeric_limits<double>::infinity();
  // 1-based: column 0 is the virtual start of every augmenting path.
  std::vector<double> u(n + 1, 0.0), v(m + 1, 0.0);
  std::vector<int> row_of_col(m + 1, 0), way(m + 1, 0);
  for (int i = 1; i <= n; ++i) {
    row_of_col[0] = i;
    int j0 = 0;
    std::vector<double> minv(m + 1, inf);
    std::vector<bool> used(m + 1, false);
    do {
      used[j0] = true;
      const int i0 = row_of_col[j0];
      double delta = inf;
      int j1 = 0;
      for (int j = 1; j <= m; ++j) {
        if (used[j]) continue;
        const double reduced = a(i0 - 1, j - 1) - u[i0] - v[j];
        if (reduced < minv[j]) {
          minv[j] = reduced;
          way[j] = j0;
        }
        if (minv[j] < delta) {
          delta = minv[j];
          j1 = j;
        }
      }
      for (int j = 0; j <= m; ++j) {
        if (used[j]) {
          u[row_of_col[j]] += delta;
          v[j] -= delta;
        } else {
          minv[j] -= delta;
        }
      }
      j0 = j1;
    } while (row_of_col[j0] != 0);
    do {  // flip the augmenting path
      const int j1 = way[j0];
      row_of_col[j0] = row_of_col[j1];
      j0 = j1;
    } while (j0 != 0);
  }
  std::vector<int> col_of_row(n, -1);
  for (int j = 1; j <= m; ++j)
    if (row_of_col[j] > 0) col_of_row[row_of_col[j] - 1] = j - 1;
  return col_of_row;
}

}  // namespace

std::vector<int> minCostAssignment(const Eigen::MatrixXd& cost) {
  if (cost.rows() == 0 || cost.cols() == 0) return std::vector<int>(cost.rows(), -1);
  if (cost.rows() <= cost.cols()) return assignRowsToCols(cost);
  const std::vector<int> row_of_col = assignRowsToCols(cost.transpose());
  std::vector<int> col_of_row(cost.rows(), -1);
  for (int j = 0; j < static_cast<int>(row_of_col.size()); ++j)
    if (row_of_col[j] >= 0) col_of_row[row_of_col[j]] = j;
  return col_of_row;
}

std::vector<int> assignAllowedPairs(int rows, int cols, const std::function<std::optional<double>(int, int)>& cost) {
  Eigen::MatrixXd c(rows, cols);
  Eigen::Matrix<bool, Eigen::Dynamic, Eigen::Dynamic> allowed(rows, cols);
  double big = 1.0;
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) {
      const std::optional<double> v = cost(i, j);
      allowed(i, j) = v.has_value();
      c(i, j) = v.value_or(0.0);
      big += std::abs(c(i, j));
    }
  // A forbidden pair costs more than all allowed pairs together, so it is only ever chosen when
  // nothing allowed is left for that row; such pairs are dropped.
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j)
      if (!allowed(i, j)) c(i, j) = big;
  std::vector<int> col = minCostAssignment(c);
  for (int i = 0; i < rows; ++i)
    if (col[i] >= 0 && !allowed(i, col[i])) col[i] = -1;
  return col;
}

}  // namespace dlslot::eval
