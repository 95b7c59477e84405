// The Hungarian algorithm for the linear assignment problem (paper III-B: "the Hungarian
// algorithm is used to solve the data association problem").
#pragma once

#include <Eigen/Core>
#include <vector>

namespace dlslot {

using Admissible = Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic>;

// Assigns rows to columns, one to one, minimising the summed cost over an assignment of
// min(rows, cols) pairs. Returns, for every row, its column or -1 (only when rows > cols).
// O(n^2 m) with n = min(rows, cols), m = max(rows, cols): shortest augmenting paths with dual
// potentials. Rectangular and empty matrices are allowed; every entry must be finite
// (std::invalid_argument otherwise).
std::vector<int> solveAssignment(const Eigen::MatrixXd& cost);

// The association problem of eq. 6-7: only `admissible` pairs may be matched (the binary score
// matrix). Returns a one-to-one set of admissible pairs with the most pairs (the maximum total
// score) and, among those, the least summed cost; for every row its column or -1. Rows and
// columns only connect through admissible pairs, so each connected component of them is solved
// on its own (exactly the same answer as one big problem, and most components of a traffic
// scene are a single trajectory and its detection). Costs of admissible pairs must be finite.
//
// Objective::LeastCost instead leaves a pair unmatched when that is cheaper: it minimises the
// summed cost of the matched admissible pairs, an unmatched row or column costing 0, so only
// admissible pairs of negative cost (a gain) are worth matching. Used where matching the most
// pairs would chain wrong matches through a crowd when some of its members were not detected.
enum class Objective { MostPairs, LeastCost };
std::vector<int> solveGatedAssignment(const Eigen::MatrixXd& cost, const Admissible& admissible,
                                      Objective objective = Objective::MostPairs);

}  // namespace dlslot
