// Gated matching for the tracking metrics: CLEAR MOT and the DontCare filter match ground truth
// to tracks by minimum total distance among the pairs the match criterion allows. The solver is
// the shared Hungarian algorithm (common/include/dlslot/hungarian.hpp).
#pragma once

#include <functional>
#include <optional>
#include <vector>

namespace dlslot::eval {

// cost(i, j) is nullopt for a pair that must not be matched (outside the gate). Returns the
// column of each row or -1, never a forbidden pair: the most allowed pairs, then the least cost.
std::vector<int> assignAllowedPairs(int rows, int cols, const std::function<std::optional<double>(int, int)>& cost);

}  // namespace dlslot::eval
