// Marginalization by the Schur complement (paper III-C, end; VINS-Mono style): the factors
// touching the states that leave the window are linearized at the current estimate,
//   H = sum J^T J,  g = sum J^T r  (robust losses applied as Ceres does),
// the leaving states m are eliminated, H* = H_rr - H_rm H_mm^-1 H_mr, g* = g_r - H_rm H_mm^-1 g_m,
// and H* = J*^T J*, J*^T r* = g* become a MarginalizationPrior on the remaining states r.
#pragma once

#include <optional>
#include <unordered_set>
#include <vector>

#include "backend/factor.hpp"

namespace dlslot::backend {

class ParallelFor;

class Marginalizer {
 public:
  // The factors' linearizations and the elimination's solves run on `parallel`'s threads when
  // given; the prior does not depend on their number.
  explicit Marginalizer(ParallelFor* parallel = nullptr) : parallel_(parallel) {}

  struct Stats {
    int leaving_dim = 0;  // tangent dimension eliminated
    int kept_dim = 0;     // tangent dimension of the new prior
    int factors = 0;      // factors folded into it
  };

  // Linearizes `factors` and eliminates the blocks in `leaving`. Blocks in `fixed` are held
  // constant (they have no tangent and drop out). Returns the prior on the other blocks the
  // factors touch, or nothing when no such block remains.
  std::optional<Factor> marginalize(const std::vector<const Factor*>& factors,
                                    const std::unordered_set<const double*>& leaving,
                                    const std::unordered_set<const double*>& fixed);
  const Stats& lastStats() const { return stats_; }

 private:
  ParallelFor* parallel_;
  Stats stats_;
};

}  // namespace dlslot::backend
