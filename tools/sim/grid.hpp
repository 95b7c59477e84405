// The spatial index of the static world: a uniform grid over the ground plane, each cell listing
// the solids whose footprint touches it, with the tallest top per cell. Rays walk the cells in
// order (2D DDA, Amanatides & Woo) and stop at the first cell beyond the nearest hit.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "solid.hpp"

namespace dlslot::sim {

class SolidGrid {
 public:
  SolidGrid(const std::vector<Solid>& solids, double cell_m = 4.0);

  // Per-thread scratch: a stamp per solid so a solid spanning several cells is tested once per ray.
  struct Scratch {
    std::vector<uint32_t> stamp;
    uint32_t ray = 0;
  };
  Scratch scratch() const { return {std::vector<uint32_t>(solids_.size(), 0), 0}; }

  // Index of the nearest solid hit by the unit ray (o, d) before max_s, or -1; s = its distance.
  // With a ray key, porous solids stop the ray inside or let it through (intersectPorous, one draw
  // per ray and solid from the key); without one, every solid is opaque.
  int cast(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double max_s, double& s, Scratch& scratch,
           const uint64_t* ray_key = nullptr) const;
  // Indices of the solids whose cells meet the axis-aligned rectangle [lo, hi] (may repeat).
  std::vector<int> near(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) const;
  const std::vector<Solid>& solids() const { return solids_; }

 private:
  bool cellOf(double x, double y, int& ix, int& iy) const;
  std::vector<Solid> solids_;
  double cell_;
  Eigen::Vector2d origin_;
  int nx_ = 0, ny_ = 0;
  std::vector<uint32_t> begin_;  // CSR: solids of cell c are index_[begin_[c] .. begin_[c+1])
  std::vector<uint32_t> index_;
  std::vector<float> top_;  // highest solid top per cell
};

}  // namespace dlslot::sim
