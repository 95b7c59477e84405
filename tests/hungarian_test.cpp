// The Hungarian solver against brute force on random matrices up to 8x8, square, rectangular
// and empty; the gated assignment of eq. 6-7 likewise.
#include <gtest/gtest.h>

#include <functional>
#include <limits>
#include <random>

#include "dlslot/hungarian.hpp"

using dlslot::Admissible;
using dlslot::solveAssignment;
using dlslot::solveGatedAssignment;

namespace {

// Minimum total cost over every one-to-one assignment of min(rows, cols) pairs, by enumeration.
double bruteForce(const Eigen::MatrixXd& c) {
  const bool tall = c.rows() > c.cols();
  const Eigen::MatrixXd a = tall ? Eigen::MatrixXd(c.transpose()) : c;  // rows <= cols
  std::vector<char> used(a.cols(), 0);
  double best = std::numeric_limits<double>::infinity();
  std::function<void(int, double)> go = [&](int row, double sum) {
    if (row == a.rows()) {
      best = std::min(best, sum);
      return;
    }
    for (int j = 0; j < a.cols(); ++j) {
      if (used[j]) continue;
      used[j] = 1;
      go(row + 1, sum + a(row, j));
      used[j] = 0;
    }
  };
  go(0, 0.0);
  return best;
}

// Checks the assignment is one to one, of the right size, and returns its cost.
double checkedCost(const Eigen::MatrixXd& c, const std::vector<int>& assignment) {
  EXPECT_EQ(assignment.size(), static_cast<size_t>(c.rows()));
  std::vector<int> hits(c.cols(), 0);
  double sum = 0;
  int pairs = 0;
  for (int i = 0; i < static_cast<int>(assignment.size()); ++i) {
    if (assignment[i] < 0) continue;
    EXPECT_LT(assignment[i], c.cols());
    ++hits[assignment[i]];
    sum += c(i, assignment[i]);
    ++pairs;
  }
  for (int h : hits) EXPECT_LE(h, 1);
  EXPECT_EQ(pairs, std::min(c.rows(), c.cols()));
  return sum;
}

// Best (most admissible pairs, then least cost) over every one-to-one set of admissible pairs.
std::pair<int, double> bruteForceGated(const Eigen::MatrixXd& c, const Admissible& ok) {
  std::vector<char> used(c.cols(), 0);
  std::pair<int, double> best{0, 0.0};
  std::function<void(int, int, double)> go = [&](int row, int pairs, double sum) {
    if (row == c.rows()) {
      if (pairs > best.first || (pairs == best.first && sum < best.second)) best = {pairs, sum};
      return;
    }
    go(row + 1, pairs, sum);  // row left unmatched
    for (int j = 0; j < c.cols(); ++j) {
      if (used[j] || !ok(row, j)) continue;
      used[j] = 1;
      go(row + 1, pairs + 1, sum + c(row, j));
      used[j] = 0;
    }
  };
  go(0, 0, 0.0);
  return best;
}

}  // namespace

TEST(TrackerHungarian, EqualsBruteForceOnRandomMatricesUpTo8x8) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> real(0.0, 10.0);
  std::uniform_int_distribution<int> small(0, 3);  // many ties
  int checked = 0;
  for (int rows = 1; rows <= 8; ++rows) {
    for (int cols = 1; cols <= 8; ++cols) {
      const int trials = rows * cols >= 49 ? 3 : 10;
      for (int trial = 0; trial < trials; ++trial) {
        Eigen::MatrixXd c(rows, cols);
        for (int i = 0; i < rows; ++i)
          for (int j = 0; j < cols; ++j) c(i, j) = trial % 2 ? real(rng) : small(rng);
        const double got = checkedCost(c, solveAssignment(c));
        EXPECT_NEAR(got, bruteForce(c), 1e-9) << rows << "x" << cols << " trial " << trial << "\n" << c;
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 500);
}

TEST(TrackerHungarian, NegativeAndLargeCosts) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> real(-1e6, 1e6);
  for (int trial = 0; trial < 20; ++trial) {
    Eigen::MatrixXd c(6, 5);
    for (int i = 0; i < c.size(); ++i) c(i) = real(rng);
    EXPECT_NEAR(checkedCost(c, solveAssignment(c)), bruteForce(c), 1e-6);
  }
}

TEST(TrackerHungarian, KnownAnswer) {
  Eigen::MatrixXd c(3, 3);
  c << 4, 1, 3,
       2, 0, 5,
       3, 2, 2;
  // Greedy would take (1,1)=0 first and pay 4+0+2 or worse; the optimum is 1+2+2 = 5.
  EXPECT_EQ(solveAssignment(c), (std::vector<int>{1, 0, 2}));
}

TEST(TrackerHungarian, RectangularLeavesExtraRowsUnassigned) {
  Eigen::MatrixXd tall(3, 1);
  tall << 5, 1, 3;
  EXPECT_EQ(solveAssignment(tall), (std::vector<int>{-1, 0, -1}));
  Eigen::MatrixXd wide(1, 3);
  wide << 5, 1, 3;
  EXPECT_EQ(solveAssignment(wide), (std::vector<int>{1}));
}

TEST(TrackerHungarian, EmptyMatrices) {
  EXPECT_TRUE(solveAssignment(Eigen::MatrixXd(0, 0)).empty());
  EXPECT_TRUE(solveAssignment(Eigen::MatrixXd(0, 4)).empty());
  EXPECT_EQ(solveAssignment(Eigen::MatrixXd(3, 0)), (std::vector<int>{-1, -1, -1}));
}

TEST(TrackerHungarian, RejectsNonFiniteCosts) {
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(2, 2);
  c(0, 1) = std::numeric_limits<double>::infinity();
  EXPECT_THROW(solveAssignment(c), std::invalid_argument);
  c(0, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(solveAssignment(c), std::invalid_argument);
}

TEST(TrackerHungarian, GatedAssignmentEqualsBruteForce) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int rows = 0; rows <= 7; ++rows) {
    for (int cols = 0; cols <= 7; ++cols) {
      for (int trial = 0; trial < 6; ++trial) {
        Eigen::MatrixXd c(rows, cols);
        Admissible ok(rows, cols);
        const double density = 0.15 + 0.15 * trial;
        for (int i = 0; i < rows; ++i)
          for (int j = 0; j < cols; ++j) {
            c(i, j) = 5.0 * u(rng) - 1.0;  // negative costs too
            ok(i, j) = u(rng) < density;
          }
        const std::vector<int> a = solveGatedAssignment(c, ok);
        ASSERT_EQ(a.size(), static_cast<size_t>(rows));
        std::vector<int> hits(cols, 0);
        int pairs = 0;
        double sum = 0;
        for (int i = 0; i < rows; ++i) {
          if (a[i] < 0) continue;
          EXPECT_TRUE(ok(i, a[i]));
          EXPECT_EQ(++hits[a[i]], 1);
          ++pairs;
          sum += c(i, a[i]);
        }
        const auto best = bruteForceGated(c, ok);
        EXPECT_EQ(pairs, best.first) << rows << "x" << cols << " trial " << trial;
        EXPECT_NEAR(sum, best.second, 1e-9) << rows << "x" << cols << " trial " << trial;
      }
    }
  }
}

TEST(TrackerHungarian, GatedAssignmentPrefersMorePairsOverLowerCost) {
  // Row 0 could take column 0 cheaply, but then row 1 (admissible only with column 0) is left out.
  Eigen::MatrixXd c(2, 2);
  c << 0.0, 10.0,
       5.0, 0.0;
  Admissible ok(2, 2);
  ok << true, true,
        true, false;
  EXPECT_EQ(solveGatedAssignment(c, ok), (std::vector<int>{1, 0}));
  EXPECT_THROW(solveGatedAssignment(c, Admissible(1, 2)), std::invalid_argument);
}

// dlslot::Objective::LeastCost: the least summed cost of the matched admissible pairs, unmatched rows and
// columns costing 0, against a brute force over every partial one-to-one set of admissible pairs.
double bruteForceLeastCost(const Eigen::MatrixXd& c, const Admissible& ok, int row = 0, std::vector<char>* used = nullptr) {
  std::vector<char> local(c.cols(), 0);
  if (!used) used = &local;
  if (row == c.rows()) return 0.0;
  double best = bruteForceLeastCost(c, ok, row + 1, used);  // row unmatched
  for (int j = 0; j < c.cols(); ++j) {
    if ((*used)[j] || !ok(row, j)) continue;
    (*used)[j] = 1;
    best = std::min(best, c(row, j) + bruteForceLeastCost(c, ok, row + 1, used));
    (*used)[j] = 0;
  }
  return best;
}

TEST(TrackerHungarian, LeastCostObjectiveEqualsBruteForce) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int rows = 0; rows <= 6; ++rows)
    for (int cols = 0; cols <= 6; ++cols)
      for (int trial = 0; trial < 6; ++trial) {
        Eigen::MatrixXd c(rows, cols);
        Admissible ok(rows, cols);
        for (int i = 0; i < rows; ++i)
          for (int j = 0; j < cols; ++j) {
            c(i, j) = 2.0 * u(rng) - 1.5;  // mostly gains (< 0), some losses
            ok(i, j) = u(rng) < 0.2 + 0.12 * trial;
          }
        const std::vector<int> a = solveGatedAssignment(c, ok, dlslot::Objective::LeastCost);
        double sum = 0;
        std::vector<int> hits(cols, 0);
        for (int i = 0; i < rows; ++i) {
          if (a[i] < 0) continue;
          EXPECT_TRUE(ok(i, a[i]));
          EXPECT_LT(c(i, a[i]), 0.0);
          EXPECT_EQ(++hits[a[i]], 1);
          sum += c(i, a[i]);
        }
        EXPECT_NEAR(sum, bruteForceLeastCost(c, ok), 1e-9) << rows << "x" << cols << " trial " << trial;
      }
}

TEST(TrackerHungarian, LeastCostLeavesAChainUnmatched) {
  // Row 0 near column 0 (gain 0.9); rows 0 and 1 could both match if row 0 took column 1 and row
  // 1 column 0, each a weak gain (0.1 + 0.1). Most pairs takes the chain, least cost the near pair.
  Eigen::MatrixXd c(2, 2);
  c << -0.9, -0.1,
       -0.1, 0.0;
  Admissible ok(2, 2);
  ok << true, true,
        true, false;
  EXPECT_EQ(solveGatedAssignment(c, ok), (std::vector<int>{1, 0}));
  EXPECT_EQ(solveGatedAssignment(c, ok, dlslot::Objective::LeastCost), (std::vector<int>{0, -1}));
}
