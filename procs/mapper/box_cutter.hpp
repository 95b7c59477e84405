// The removal test of a keyframe's points against the boxes of the objects taken out of the map,
// all in the lidar frame. Every point of every keyframe meets it, so it is built once per keyframe:
// each box with its heading's sine and cosine, and a coarse grid over the ground plane listing the
// boxes whose footprint reaches each cell. Most points lie in cells no box reaches and cost one
// look-up instead of a test against every box (highway: 30-40 boxes, ~100 k points a keyframe).
//
// The boxes move: a point is tested against its box where the object was, relative to the lidar,
// when the lidar fired at it (sweep_timing.hpp; the firing time is computed only for points in a
// cell some box reaches).
#pragma once

#include <cstdint>
#include <vector>

#include "dlslot/sweep_timing.hpp"
#include "dlslot/types.hpp"

namespace dlslot::mapper {

class BoxCutter {
 public:
  // boxes: lidar frame (yaw about the lidar's z), with their motion relative to the lidar; reach_m:
  // the grid covers |x|, |y| <= reach_m (points beyond are tested against every box, so the answer
  // never depends on the grid).
  BoxCutter(const std::vector<MovingBox>& boxes, double reach_m, const SweepTiming& sweep = {0.0, true});
  // True when p lies inside one of the boxes at p's firing time (MovingBox::at, no margin).
  bool inside(const Eigen::Vector3f& p) const {
    const int cell = cellOf(p.x(), p.y());
    if (cell < 0) return insideAny(p, 0, static_cast<int>(cuts_.size()), nullptr);
    return insideAny(p, start_[cell], start_[cell + 1], order_.data());
  }
  size_t boxes() const { return cuts_.size(); }

 private:
  struct Cut {
    Eigen::Vector3f center, half, velocity;
    float c, s, yaw_rate;
  };
  int cellOf(float x, float y) const {
    const int ix = static_cast<int>((x + reach_) * inverse_cell_), iy = static_cast<int>((y + reach_) * inverse_cell_);
    if (x < -reach_ || y < -reach_ || ix >= side_ || iy >= side_) return -1;
    return iy * side_ + ix;
  }
  // The cuts [begin, end) of `order` (or of cuts_ when order is null); the firing time is computed
  // only when some box is to be tested.
  bool insideAny(const Eigen::Vector3f& p, int begin, int end, const uint16_t* order) const {
    if (begin >= end) return false;
    const float t = static_cast<float>(sweep_.firingTime(p.x(), p.y()));
    for (int k = begin; k < end; ++k) {
      const Cut& b = cuts_[order ? order[k] : k];
      const Eigen::Vector3f d = p - (b.center + t * b.velocity);
      // The heading at t to first order (|yaw_rate t| is a few hundredths of a radian).
      const float dy = t * b.yaw_rate, c = b.c - b.s * dy, s = b.s + b.c * dy;
      if (std::abs(c * d.x() + s * d.y()) <= b.half.x() && std::abs(-s * d.x() + c * d.y()) <= b.half.y() &&
          std::abs(d.z()) <= b.half.z())
        return true;
    }
    return false;
  }

  static constexpr float kCellM = 2.0f;  // about half a car: a box reaches few cells, a cell holds few boxes
  std::vector<Cut> cuts_;
  SweepTiming sweep_;
  float reach_, inverse_cell_;
  int side_;
  std::vector<int> start_;        // cell -> first entry of order_ (CSR), side_^2 + 1 entries
  std::vector<uint16_t> order_;   // box indices by cell
};

}  // namespace dlslot::mapper
