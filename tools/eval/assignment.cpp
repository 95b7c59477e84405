#include "assignment.hpp"

#include "dlslot/hungarian.hpp"

namespace dlslot::eval {

std::vector<int> assignAllowedPairs(int rows, int cols, const std::function<std::optional<double>(int, int)>& cost) {
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(rows, cols);
  Admissible allowed(rows, cols);
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) {
      const std::optional<double> v = cost(i, j);
      allowed(i, j) = v.has_value();
      c(i, j) = v.value_or(0.0);
    }
  return solveGatedAssignment(c, allowed);
}

}  // namespace dlslot::eval
