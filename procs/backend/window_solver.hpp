// Levenberg-Marquardt for the window's problem (eq. 12), on the factors' Ceres cost functions
// and the PoseManifold, with a linear solver shaped like the window: each dynamic object's
// chain of poses and pose changes (a "group") touches only itself and a few shared blocks (the
// "separator": ego poses, landmarks, the prior's blocks). Every group is eliminated with its
// own block-banded Cholesky (a Schur complement, as Ceres' SCHUR solvers do for single blocks),
// then the separator is solved densely. The marginalization prior is dense over its blocks, so
// the separator is a dense matrix anyway; no general sparse factorization is needed.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <optional>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "backend/dense_kernels.hpp"
#include "backend/factor.hpp"
#include "backend/factor_linearization.hpp"
#include "backend/parallel_for.hpp"
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
  // The groups' work (linearization, elimination, substitution) is spread over `parallel`'s
  // threads when given; the result does not depend on their number.
  Summary solve(const std::vector<const Factor*>& factors, const std::vector<double*>& separator,
                const std::vector<std::vector<double*>>& groups, const std::unordered_set<const double*>& fixed,
                int tail, const Options& options, ParallelFor* parallel = nullptr);

  // Marginal covariance in the PoseManifold's tangent, from the last linearization: exact for
  // the separator's tail blocks; for a group block, exact when every separator block the group
  // touches is in the tail, else without the correlations through the others.
  std::optional<Matrix6> covariance(const double* block) const;
  // The joint marginal covariance of blocks of one group, or of the separator's tail (6 rows and
  // columns each, in the order given); none for blocks of different groups.
  std::optional<Eigen::MatrixXd> jointCovariance(const std::vector<const double*>& blocks) const;

 private:
  // Row-major: the substitutions below work on rows of 6x6 blocks.
  using RowMatrix = dense::RowMatrix;
  // Cholesky factor of a symmetric positive definite matrix of 6x6 blocks that is zero beyond
  // `w` blocks from the diagonal (a group is a chain in time: o_f and c_f interleaved couple
  // only to their neighbours), kept as its band of lower 6x6 blocks.
  struct BandCholesky {
    int m = 0, w = 0;
    std::vector<Matrix6> L;  // L(i, i - d) at [i * (w + 1) + d]
    std::vector<Matrix6> L_inv;  // L(i, i)^-1: substitution by products (6x6 solves are slow)
    // Factors the band `H` (same layout) damped by mu diag(H); false when not definite.
    bool compute(const std::vector<Matrix6>& H, int m, int w, double mu);
    // B <- L^-1 B (B: 6m rows). With `widths`, row block i of B is zero beyond widths[i]
    // columns (widths growing with i; C's staircase) and only those are touched.
    void solveL(RowMatrix& B, const std::vector<int>* widths = nullptr) const;
    void solveLt(RowMatrix& B) const;  // B <- L^-T B
  };
  // A group is self-contained: its factors (those touching its blocks) are linearized into
  // its own band, coupling C and the part of the separator's Hessian (D) and gradient (g_touched)
  // they contribute, so groups can be worked on in parallel.
  struct Group {
    std::vector<double*> blocks;  // estimated ones, in time order
    std::vector<int> factors;     // indices of the factors touching them
    int m = 0, w = 0;             // blocks, block bandwidth
    std::vector<Matrix6> H;       // undamped band (BandCholesky layout)
    Eigen::VectorXd g, g_touched;  // gradient on the group's blocks and on the touched ones
    std::vector<int> touched;     // separator block indices
    // Columns of C that can be non-zero in each block row: an ego pose X_f couples to the
    // chain from o_f on, so C (and Y) are a staircase when the touched blocks come in time order.
    std::vector<int> widths;
    BandCholesky chol;
    // Linearized, then eliminated in place by factor() (no copies of these, the largest of a
    // group's matrices):
    RowMatrix Y;        // 6m x 6|touched|: the coupling C to the touched separator blocks, then L^-1 C
    Eigen::MatrixXd S;  // the factors' Hessian D among the touched blocks (lower blocks), then D - Y^T Y
    RowMatrix z;                  // substitute(): L^-1 g, then the step
    Eigen::VectorXd Ytz;          // substitute(): Y^T z
  };
  // Where a factor's block lives: a separator block, a group's block, or nowhere (fixed).
  struct Slot {
    int group = -2;   // -1: separator, -2: fixed, else the group
    int index = 0;    // block index in the separator or in the group
    int column = -1;  // separator block of a group's factor: its column offset in the group's Y
  };

  void setUp(const std::vector<double*>& separator, const std::vector<std::vector<double*>>& groups,
             const std::unordered_set<const double*>& fixed, int tail);
  // Each factor's slots and group, the separator blocks each group touches and its bandwidth.
  void mapFactors(const std::vector<const Factor*>& factors);
  // Calls work(i) for each item: 0 the separator's own factors, k + 1 group k.
  void forEachItem(const std::function<void(int)>& work);
  // The sum of work(item) over the items, in item order (the same for any thread count).
  double sumOverItems(const std::function<double(int)>& work);
  const std::vector<int>& itemFactors(int item) const {
    return item == 0 ? separator_factors_ : groups_[item - 1].factors;
  }
  // Linearizes every factor, assembles the gradient and the undamped Gauss-Newton Hessian;
  // returns the cost there.
  double linearizeAll(const std::vector<const Factor*>& factors, const std::unordered_set<const double*>& fixed);
  double totalCost(const std::vector<const Factor*>& factors);
  // Factors the Hessian damped by mu (Levenberg-Marquardt, as Ceres: H + mu diag(H)): the
  // groups' band Cholesky and Schur complements, then the separator's dense Cholesky. False
  // when one fails. Uses up the groups' linearization (Y, S): factoring again needs a new one.
  bool factor(double mu);
  // The step for the current gradient from the last factorization, into step_sep_ and
  // step_groups_.
  void substitute();
  double modelCostChange();
  Vector6 stepOf(const Slot& s) const;

  ParallelFor* parallel_ = nullptr;
  std::vector<double*> separator_;
  std::vector<Group> groups_;
  std::vector<int> separator_factors_;  // factors touching no group
  std::vector<double> item_sums_;       // per item, summed in item order (deterministic)
  std::unordered_map<const double*, Slot> where_;
  std::vector<std::vector<Slot>> slots_;  // per factor, per block
  int n_sep_ = 0, tail_dim_ = 0;
  std::vector<FactorLinearization> lin_;
  Eigen::MatrixXd H_sep_;  // undamped, of the separator's own factors only (lower triangle)
  Eigen::VectorXd g_sep_;  // of all factors
  Eigen::VectorXd diag_sep_;  // of the whole separator Hessian (H_sep_ and the groups' D), for damping
  // Damped, after them; factor() leaves the separator's Cholesky factor in its lower triangle.
  Eigen::MatrixXd H_reduced_;
  Eigen::VectorXd step_sep_;
  std::vector<Eigen::VectorXd> step_groups_;
  double max_gradient_ = 0;
  int linearizations_ = 0, factored_linearization_ = -1;  // which linearization factor() used
  Eigen::MatrixXd tail_cov_;  // joint covariance of the tail blocks
};

}  // namespace dlslot::backend
