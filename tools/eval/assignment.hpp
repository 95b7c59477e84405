// Minimum-cost assignment (Hungarian algorithm) for the per-frame matching of the tracking
// metrics: CLEAR MOT matches ground truth to tracks by minimum total distance, HOTA by maximum
// alignment score.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <optional>
#include <vector>

namespace dlslot::eval {

// Assigns rows to columns so that min(rows, cols) pairs are made with the least total cost.
// Returns, for each row, its column or -1. Callers mark impossible pairs with a cost larger than
// the sum of all possible ones and drop them afterwards; the assignment then has the most
// possible pairs first and the least cost among those.
std::vector<int> minCostAssignment(const Eigen::MatrixXd& cost);

// The same when only some pairs are allowed: cost(i, j) is nullopt for a pair that must not be
// matched (outside the gate). Returns the column of each row or -1, never a forbidden pair.
std::vector<int> assignAllowedPairs(int rows, int cols, const std::function<std::optional<double>(int, int)>& cost);

}  // namespace dlslot::eval
