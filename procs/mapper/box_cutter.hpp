// The removal test of a keyframe's points against the boxes of the objects taken out of the map,
// all in the lidar frame. Every point of every keyframe meets it, so it is built once per keyframe:
// each box with its heading's sine and cosine, and a coarse grid over the ground plane listing the
// boxes whose footprint reaches each cell. Most points lie in cells no box reaches and cost one
// look-up instead of a test against every box (highway: 30-40 boxes, ~100 k points a keyframe).
#pragma once

#include <cstdint>
#include <vector>

#include "dlslot/types.hpp"

namespace dlslot::mapper {

class BoxCutter {
 public:
  // boxes: lidar frame (yaw about the lidar's z); reach_m: the grid covers |x|, |y| <= reach_m
  // (points beyond are tested against every box, so the answer never depends on the grid).
  BoxCutter(const std::vector<Box>& boxes, double reach_m);
  // True when p lies inside one of the boxes (Box::contains with no margin).
  bool inside(const Eigen::Vector3f& p) const {
    const int cell = cellOf(p.x(), p.y());
    if (cell < 0) return insideAny(p, 0, static_cast<int>(cuts_.size()), nullptr);
    return insideAny(p, start_[cell], start_[cell + 1], order_.data());
  }
  size_t boxes() const { return cuts_.size(); }

 private:
  struct Cut {
    Eigen::Vector3f center, half;
    float c, s;
  };
  int cellOf(float x, float y) const {
    const int ix = static_cast<int>((x + reach_) * inverse_cell_), iy = static_cast<int>((y + reach_) * inverse_cell_);
    if (x < -reach_ || y < -reach_ || ix >= side_ || iy >= side_) return -1;
    return iy * side_ + ix;
  }
  // The cuts [begin, end) of `order` (or of cuts_ when order is null).
  bool insideAny(const Eigen::Vector3f& p, int begin, int end, const uint16_t* order) const {
    for (int k = begin; k < end; ++k) {
      const Cut& b = cuts_[order ? order[k] : k];
      const Eigen::Vector3f d = p - b.center;
      if (std::abs(b.c * d.x() + b.s * d.y()) <= b.half.x() && std::abs(-b.s * d.x() + b.c * d.y()) <= b.half.y() &&
          std::abs(d.z()) <= b.half.z())
        return true;
    }
    return false;
  }

  static constexpr float kCellM = 2.0f;  // about half a car: a box reaches few cells, a cell holds few boxes
  std::vector<Cut> cuts_;
  float reach_, inverse_cell_;
  int side_;
  std::vector<int> start_;        // cell -> first entry of order_ (CSR), side_^2 + 1 entries
  std::vector<uint16_t> order_;   // box indices by cell
};

}  // namespace dlslot::mapper
