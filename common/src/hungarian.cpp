#include "dlslot/hungarian.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace dlslot {
namespace {

// The square-or-wide case (n <= m). Rows are added one at a time; each addition grows a tree of
// tight edges (reduced cost zero under the potentials u, v) from the new row until it reaches a
// free column, adjusting the potentials by the smallest slack when the tree gets stuck, then
// flips the path. Column 0 is a sentinel that holds the row being inserted.
std::vector<int> solveWide(const Eigen::MatrixXd& c) {
  const int n = static_cast<int>(c.rows()), m = static_cast<int>(c.cols());
  constexpr double kInf = std::numeric_limits<double>::infinity();
  std::vector<double> u(n + 1, 0.0), v(m + 1, 0.0);
  std::vector<int> row_of(m + 1, 0);   // row (1-based) matched to column j, 0 = free
  std::vector<int> parent(m + 1, 0);   // previous column on the alternating path
  std::vector<double> slack(m + 1);
  std::vector<char> in_tree(m + 1);

  for (int i = 1; i <= n; ++i) {
    row_of[0] = i;
    int col = 0;
    std::fill(slack.begin(), slack.end(), kInf);
    std::fill(in_tree.begin(), in_tree.end(), 0);
    do {
      in_tree[col] = 1;
      const int row = row_of[col];
      double delta = kInf;
      int next = 0;
      for (int j = 1; j <= m; ++j) {
        if (in_tree[j]) continue;
        const double reduced = c(row - 1, j - 1) - u[row] - v[j];
        if (reduced < slack[j]) {
          slack[j] = reduced;
          parent[j] = col;
        }
        if (slack[j] < delta) {
          delta = slack[j];
          next = j;
        }
      }
      for (int j = 0; j <= m; ++j) {
        if (in_tree[j]) {
          u[row_of[j]] += delta;
          v[j] -= delta;
        } else {
          slack[j] -= delta;
        }
      }
      col = next;
    } while (row_of[col] != 0);
    // Augment: shift the matches back along the path to the sentinel.
    while (col != 0) {
      const int prev = parent[col];
      row_of[col] = row_of[prev];
      col = prev;
    }
  }

  std::vector<int> col_of_row(n, -1);
  for (int j = 1; j <= m; ++j)
    if (row_of[j] != 0) col_of_row[row_of[j] - 1] = j - 1;
  return col_of_row;
}

// Union-find over rows (0..U-1) and columns (U..U+V-1).
struct Components {
  std::vector<int> parent;
  explicit Components(int n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  }
  void join(int a, int b) { parent[find(a)] = find(b); }
};

}  // namespace

std::vector<int> solveAssignment(const Eigen::MatrixXd& cost) {
  if (!cost.allFinite()) throw std::invalid_argument("solveAssignment: every cost must be finite");
  if (cost.rows() == 0 || cost.cols() == 0) return std::vector<int>(cost.rows(), -1);
  if (cost.rows() <= cost.cols()) return solveWide(cost);

  // Tall: assign the columns to rows instead, then invert the answer.
  const std::vector<int> row_of_col = solveWide(cost.transpose());
  std::vector<int> col_of_row(cost.rows(), -1);
  for (int j = 0; j < static_cast<int>(row_of_col.size()); ++j) col_of_row[row_of_col[j]] = j;
  return col_of_row;
}

std::vector<int> solveGatedAssignment(const Eigen::MatrixXd& cost, const Admissible& admissible, Objective objective) {
  if (cost.rows() != admissible.rows() || cost.cols() != admissible.cols())
    throw std::invalid_argument("solveGatedAssignment: cost and admissible differ in size");
  const int U = static_cast<int>(cost.rows()), V = static_cast<int>(cost.cols());
  Components comp(U + V);
  for (int u = 0; u < U; ++u)
    for (int v = 0; v < V; ++v)
      if (admissible(u, v)) comp.join(u, U + v);

  std::vector<std::vector<int>> rows_of(U + V), cols_of(U + V);
  for (int u = 0; u < U; ++u) rows_of[comp.find(u)].push_back(u);
  for (int v = 0; v < V; ++v) cols_of[comp.find(U + v)].push_back(v);

  std::vector<int> col_of_row(U, -1);
  for (int root = 0; root < U + V; ++root) {
    const std::vector<int>& rows = rows_of[root];
    const std::vector<int>& cols = cols_of[root];
    if (rows.empty() || cols.empty()) continue;
    const bool least_cost = objective == Objective::LeastCost;
    if (rows.size() == 1 && cols.size() == 1) {  // the common case: one trajectory, one detection
      if (!least_cost || cost(rows[0], cols[0]) < 0) col_of_row[rows[0]] = cols[0];
      continue;
    }
    if (least_cost) {
      // A pair costing >= 0, or not admissible, is worth no more than leaving both unmatched
      // (cost 0): with every entry <= 0 a full assignment's cost is that of its gainful pairs.
      Eigen::MatrixXd c(rows.size(), cols.size());
      for (size_t i = 0; i < rows.size(); ++i)
        for (size_t j = 0; j < cols.size(); ++j)
          c(i, j) = admissible(rows[i], cols[j]) ? std::min(cost(rows[i], cols[j]), 0.0) : 0.0;
      const std::vector<int> a = solveAssignment(c);
      for (size_t i = 0; i < rows.size(); ++i)
        if (a[i] >= 0 && admissible(rows[i], cols[a[i]]) && cost(rows[i], cols[a[i]]) < 0)
          col_of_row[rows[i]] = cols[a[i]];
      continue;
    }
    // Shift the admissible costs to >= 0; an inadmissible pair then costs more than any set of
    // admissible pairs could, so the solver first maximises the number of admissible pairs.
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (int u : rows)
      for (int v : cols)
        if (admissible(u, v)) {
          lo = std::min(lo, cost(u, v));
          hi = std::max(hi, cost(u, v));
        }
    const double forbidden = std::min(rows.size(), cols.size()) * (hi - lo) + 1.0;
    Eigen::MatrixXd c(rows.size(), cols.size());
    for (size_t i = 0; i < rows.size(); ++i)
      for (size_t j = 0; j < cols.size(); ++j)
        c(i, j) = admissible(rows[i], cols[j]) ? cost(rows[i], cols[j]) - lo : forbidden;
    const std::vector<int> a = solveAssignment(c);
    for (size_t i = 0; i < rows.size(); ++i)
      if (a[i] >= 0 && admissible(rows[i], cols[a[i]])) col_of_row[rows[i]] = cols[a[i]];
  }
  return col_of_row;
}

}  // namespace dlslot
