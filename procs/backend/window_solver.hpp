// Levenberg-Marquardt for the window's problem (eq. 12), on the factors' Ceres cost functions
// and the PoseManifold, with a linear solver shaped like the window: each dynamic object's
// chain of poses and pose changes (a "group") touches only itself and a few shared blocks (the
// "separator": ego poses, landmarks, the prior's blocks). Every group is eliminated with its
// own dense Cholesky (a Schur complement, as Ceres' SCHUR solvers do for single blocks), then
// the separator is solved densely. The marginalization prior is dense over its blocks, so the
// separator is a dense matrix anyway; no general sparse factorization is needed.
#pragma once

#include <Eigen/Cholesky>
#include <optional>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "backend/factor.hpp"
#include "backend/factor_linearization.hpp"
#include "backend/se3.hpp"

namespace dlslot::backend {

class WindowSolver {
 public:
  struct Options {
    int max_iterations = 3;
    double function_tolerance = 1e-6;   // |cost change| / cost
    double gradient_tolerance = 1e-10;  // max |gradient|
    double parameter_tolerance = 1e-8;  // |step| / (|x| + tol)
    // Large: the window starts from the last solution, so Gauss-Newton steps (mu -> 0) are
    // what it needs; rejected steps shrink the radius. Covariances also want mu -> 0.
    double initial_trust_region_radius = 1e8;
    bool covariance = true;  // prepare covariance() (may cost one more factorization)
  };
  struct Summary {
    int iterations = 0;  // steps tried (accepted or not)
    double initial_cost = 0, final_cost = 0;
  };

  // Minimizes the factors' cost over every block in `separator` and `groups` not in `fixed`.
  // No factor may touch two groups, and a MarginalizationPrior only separator blocks. The last
  // `tail` separator blocks get joint marginal covariances (see covariance()).
  Summary solve(const std::vector<const Factor*>& factors, const std::vector<double*>& separator,
                const std::vector<std::vector<double*>>& groups, const std::unordered_set<const double*>& fixed,
                int tail, const Options& options);

  // Marginal covariance in the PoseManifold's tangent, from the last linearization: exact for
  // the separator's tail blocks; for a group block, exact when every separator block the group
  // touches is in the tail, else without the correlations through the others.
  std::optional<Matrix6> covariance(const double* block) const;

 private:
  // In-place Cholesky of a banded symmetric positive definite matrix (lower factor).
  struct BandedCholesky {
    Eigen::MatrixXd L;
    int n = 0, bw = 0;
    bool compute(const Eigen::MatrixXd& A);
    // Row-major right-hand sides: substitution works row by row.
    using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
    void solveL(RowMatrix& B) const;   // B <- L^-1 B
    void solveLt(RowMatrix& B) const;  // B <- L^-T B
  };
  struct Group {
    std::vector<double*> blocks;  // estimated ones
    int n = 0;
    Eigen::MatrixXd H, C;  // undamped; H: n x n; C: n x 6|touched|, coupling to the touched separator blocks
    Eigen::VectorXd g;
    std::vector<int> touched;  // separator block indices
    std::unordered_map<int, int> column;  // separator block index -> column offset in C
    BandedCholesky chol;
    BandedCholesky::RowMatrix Y;  // L^-1 [C g]
  };
  struct Location {
    int group = -1;  // -1: separator
    int offset = 0;  // tangent offset in the separator or the group
    int index = 0;   // separator block index (separator only)
  };

  void setUp(const std::vector<double*>& separator, const std::vector<std::vector<double*>>& groups,
             const std::unordered_set<const double*>& fixed, int tail);
  // Which separator blocks each group's factors touch (fixed for one solve).
  void findCouplings(const std::vector<const Factor*>& factors);
  // Linearizes every factor and assembles the undamped normal equations.
  void linearizeAll(const std::vector<const Factor*>& factors, const std::unordered_set<const double*>& fixed);
  // Solves the system damped by mu; false when a Cholesky fails.
  bool solveStep(double mu, Eigen::VectorXd& step_sep, std::vector<Eigen::VectorXd>& step_groups);
  double modelCostChange(const std::vector<const Factor*>& factors, const Eigen::VectorXd& step_sep,
                         const std::vector<Eigen::VectorXd>& step_groups) const;
  Eigen::VectorXd stepOf(const double* block, const Eigen::VectorXd& step_sep,
                         const std::vector<Eigen::VectorXd>& step_groups) const;

  std::vector<double*> separator_;
  std::vector<Group> groups_;
  std::unordered_map<const double*, Location> where_;
  int n_sep_ = 0, tail_dim_ = 0;
  std::vector<FactorLinearization> lin_;
  Eigen::MatrixXd H_sep_;  // undamped, before the groups' Schur complements
  Eigen::VectorXd g_sep_;
  double max_gradient_ = 0;
  Eigen::LLT<Eigen::MatrixXd> sep_llt_;
  Eigen::MatrixXd tail_cov_;  // joint covariance of the tail blocks
};

}  // namespace dlslot::backend
