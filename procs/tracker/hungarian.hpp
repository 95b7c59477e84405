// The Hungarian algorithm for the linear assignment problem (paper III-B: "the Hungarian
// algorithm is used to solve the data association problem").
#pragma once

#include <Eigen/Core>
#include <vector>

namespace dlslot::tracker {

// Assigns rows to columns, one to one, minimising the summed cost over an assignment of
// min(rows, cols) pairs. Returns, for every row, its column or -1 (only when rows > cols).
// O(n^2 m) with n = min(rows, cols), m = max(rows, cols): shortest augmenting paths with dual
// potentials. Rectangular and empty matrices are allowed; every entry must be finite
// (std::invalid_argument otherwise): express "forbidden" with a large finite cost.
std::vector<int> solveAssignment(const Eigen::MatrixXd& cost);

}  // namespace dlslot::tracker
