#include "grid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "rng.hpp"

namespace dlslot::sim {

SolidGrid::SolidGrid(const std::vector<Solid>& solids, double cell_m) : solids_(solids), cell_(cell_m) {
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::max()), hi = -lo;
  for (const Solid& s : solids_) {
    const double r = s.radiusXY();
    lo = lo.cwiseMin(s.center.head<2>() - Eigen::Vector2d::Constant(r));
    hi = hi.cwiseMax(s.center.head<2>() + Eigen::Vector2d::Constant(r));
  }
  if (solids_.empty()) lo = hi = Eigen::Vector2d::Zero();
  origin_ = lo - Eigen::Vector2d::Constant(cell_);
  nx_ = static_cast<int>(std::ceil((hi.x() - origin_.x()) / cell_)) + 1;
  ny_ = static_cast<int>(std::ceil((hi.y() - origin_.y()) / cell_)) + 1;
  const size_t cells = static_cast<size_t>(nx_) * ny_;
  top_.assign(cells, -std::numeric_limits<float>::infinity());
  // Two passes (count, fill) over each solid's footprint cells.
  std::vector<uint32_t> count(cells + 1, 0);
  auto forCells = [&](const Solid& s, auto&& f) {
    const double r = s.radiusXY();
    int x0, y0, x1, y1;
    cellOf(s.center.x() - r, s.center.y() - r, x0, y0);
    cellOf(s.center.x() + r, s.center.y() + r, x1, y1);
    for (int iy = y0; iy <= y1; ++iy)
      for (int ix = x0; ix <= x1; ++ix) f(static_cast<size_t>(iy) * nx_ + ix);
  };
  for (const Solid& s : solids_) forCells(s, [&](size_t c) { ++count[c + 1]; });
  begin_.assign(cells + 1, 0);
  for (size_t c = 0; c < cells; ++c) begin_[c + 1] = begin_[c] + count[c + 1];
  index_.resize(begin_[cells]);
  std::vector<uint32_t> fill(begin_.begin(), begin_.end() - 1);
  for (size_t i = 0; i < solids_.size(); ++i)
    forCells(solids_[i], [&](size_t c) {
      index_[fill[c]++] = static_cast<uint32_t>(i);
      top_[c] = std::max(top_[c], static_cast<float>(solids_[i].zMax()));
    });
}

bool SolidGrid::cellOf(double x, double y, int& ix, int& iy) const {
  ix = static_cast<int>(std::floor((x - origin_.x()) / cell_));
  iy = static_cast<int>(std::floor((y - origin_.y()) / cell_));
  const bool inside = ix >= 0 && iy >= 0 && ix < nx_ && iy < ny_;
  ix = std::clamp(ix, 0, nx_ - 1);
  iy = std::clamp(iy, 0, ny_ - 1);
  return inside;
}

int SolidGrid::cast(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double max_s, double& s, Scratch& scratch,
                    const uint64_t* ray_key) const {
  if (solids_.empty()) return -1;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  // Clip the ray to the grid's rectangle.
  double t0 = 0, t1 = max_s;
  for (int a = 0; a < 2; ++a) {
    const double lo = origin_[a], hi = origin_[a] + (a == 0 ? nx_ : ny_) * cell_;
    if (std::abs(d[a]) < 1e-12) {
      if (o[a] < lo || o[a] >= hi) return -1;
      continue;
    }
    double ta = (lo - o[a]) / d[a], tb = (hi - o[a]) / d[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  if (t0 >= t1) return -1;
  if (++scratch.ray == 0) {  // stamp counter wrapped: clear the stamps
    std::fill(scratch.stamp.begin(), scratch.stamp.end(), 0);
    scratch.ray = 1;
  }
  const Eigen::Vector3d start = o + t0 * d;
  int ix, iy;
  cellOf(start.x(), start.y(), ix, iy);
  const int step_x = d.x() > 0 ? 1 : -1, step_y = d.y() > 0 ? 1 : -1;
  const double next_x = origin_.x() + (ix + (step_x > 0 ? 1 : 0)) * cell_;
  const double next_y = origin_.y() + (iy + (step_y > 0 ? 1 : 0)) * cell_;
  double t_max_x = std::abs(d.x()) < 1e-12 ? kInf : (next_x - o.x()) / d.x();
  double t_max_y = std::abs(d.y()) < 1e-12 ? kInf : (next_y - o.y()) / d.y();
  const double t_dx = std::abs(d.x()) < 1e-12 ? kInf : cell_ / std::abs(d.x());
  const double t_dy = std::abs(d.y()) < 1e-12 ? kInf : cell_ / std::abs(d.y());

  int best = -1;
  double best_s = t1;
  double t_in = t0;
  while (t_in < best_s) {
    const double t_out = std::min({t_max_x, t_max_y, t1});
    const size_t c = static_cast<size_t>(iy) * nx_ + ix;
    const double z_low = o.z() + d.z() * (d.z() < 0 ? t_out : t_in);  // lowest the ray gets in this cell
    if (begin_[c] != begin_[c + 1] && z_low <= top_[c]) {
      for (uint32_t k = begin_[c]; k < begin_[c + 1]; ++k) {
        const uint32_t i = index_[k];
        if (scratch.stamp[i] == scratch.ray) continue;
        scratch.stamp[i] = scratch.ray;
        double hit;
        const Solid& solid = solids_[i];
        const bool hits = ray_key && solid.mean_free_path > 0
                              ? intersectPorous(solid, o, d, best_s, Rng(streamKey({*ray_key, i})).uniform(), hit)
                              : intersect(solid, o, d, best_s, hit);
        if (hits) {
          best_s = hit;
          best = static_cast<int>(i);
        }
      }
    }
    if (t_out >= t1) break;
    if (t_max_x < t_max_y) {
      ix += step_x;
      t_in = t_max_x;
      t_max_x += t_dx;
    } else {
      iy += step_y;
      t_in = t_max_y;
      t_max_y += t_dy;
    }
    if (ix < 0 || iy < 0 || ix >= nx_ || iy >= ny_) break;
  }
  if (best >= 0) s = best_s;
  return best;
}

std::vector<int> SolidGrid::near(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) const {
  std::vector<int> out;
  if (solids_.empty()) return out;
  int x0, y0, x1, y1;
  cellOf(lo.x(), lo.y(), x0, y0);
  cellOf(hi.x(), hi.y(), x1, y1);
  for (int iy = y0; iy <= y1; ++iy)
    for (int ix = x0; ix <= x1; ++ix) {
      const size_t c = static_cast<size_t>(iy) * nx_ + ix;
      for (uint32_t k = begin_[c]; k < begin_[c + 1]; ++k) out.push_back(static_cast<int>(index_[k]));
    }
  return out;
}

}  // namespace dlslot::sim
