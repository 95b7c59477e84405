// One factor of the window's graph: a cost function, an optional robust loss, and the pose
// blocks it connects. Factors are kept across solves (the problem is rebuilt from them each
// frame) and handed to the Marginalizer when a block they touch leaves the window.
#pragma once

#include <ceres/cost_function.h>
#include <ceres/loss_function.h>

#include <algorithm>
#include <memory>
#include <vector>

namespace dlslot::backend {

struct Factor {
  std::shared_ptr<ceres::CostFunction> cost;
  std::shared_ptr<ceres::LossFunction> loss;  // null: plain squared residual
  std::vector<double*> blocks;

  bool touches(const double* block) const {
    return std::find(blocks.begin(), blocks.end(), block) != blocks.end();
  }
};

}  // namespace dlslot::backend
