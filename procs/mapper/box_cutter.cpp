#include "mapper/box_cutter.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace dlslot::mapper {

BoxCutter::BoxCutter(const std::vector<MovingBox>& boxes, double reach_m, const SweepTiming& sweep)
    : sweep_(sweep), reach_(static_cast<float>(reach_m)), inverse_cell_(1.0f / kCellM) {
  if (!(reach_m > 0)) throw std::invalid_argument("BoxCutter: reach must be > 0");
  if (boxes.size() > 65535) throw std::invalid_argument("BoxCutter: more than 65535 boxes");
  side_ = static_cast<int>(std::ceil(2 * reach_m / kCellM));
  std::vector<std::vector<uint16_t>> cells(static_cast<size_t>(side_) * side_);
  const double t_max = sweep_.maxOffset();
  for (const MovingBox& m : boxes) {
    const Box& b = m.box;
    const uint16_t index = static_cast<uint16_t>(cuts_.size());
    cuts_.push_back({b.center.cast<float>(), 0.5f * b.size.cast<float>(), m.velocity.cast<float>(),
                     static_cast<float>(std::cos(b.yaw)), static_cast<float>(std::sin(b.yaw)),
                     static_cast<float>(m.yaw_rate)});
    // The cells the footprint's bounding circle reaches over the sweep (a cell is listed if it may
    // hold a point inside).
    const double r = 0.5 * b.size.head<2>().norm() + t_max * m.velocity.head<2>().norm();
    const auto clampCell = [&](double v) {
      return std::clamp(static_cast<int>(std::floor((v + reach_m) / kCellM)), 0, side_ - 1);
    };
    const int x0 = clampCell(b.center.x() - r), x1 = clampCell(b.center.x() + r);
    const int y0 = clampCell(b.center.y() - r), y1 = clampCell(b.center.y() + r);
    for (int iy = y0; iy <= y1; ++iy)
      for (int ix = x0; ix <= x1; ++ix) cells[static_cast<size_t>(iy) * side_ + ix].push_back(index);
  }
  start_.assign(cells.size() + 1, 0);
  for (size_t c = 0; c < cells.size(); ++c) start_[c + 1] = start_[c] + static_cast<int>(cells[c].size());
  order_.reserve(static_cast<size_t>(start_.back()));
  for (const auto& c : cells) order_.insert(order_.end(), c.begin(), c.end());
}

}  // namespace dlslot::mapper
