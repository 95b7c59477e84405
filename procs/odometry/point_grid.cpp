#include "point_grid.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace dlslot::odometry {

int64_t PointGrid::key(int64_t x, int64_t y, int64_t z) const {
  const int64_t off = int64_t{1} << 20;  // 21 bits per axis
  return ((x + off) << 42) | ((y + off) << 21) | (z + off);
}

int64_t PointGrid::cellOf(float v) const { return static_cast<int64_t>(std::floor(v / cell_)); }

void PointGrid::build(const FeatureCloud& cloud) {
  cells_.clear();
  start_.clear();
  const size_t n = cloud.size();
  // Counting sort by cell: number the cells in order of first appearance, count, place.
  std::vector<int> cell_of(n);
  std::vector<int> count;
  lo_.setConstant(INT64_MAX);
  hi_.setConstant(INT64_MIN);
  for (size_t i = 0; i < n; ++i) {
    const auto& p = cloud[i];
    const Eigen::Matrix<int64_t, 3, 1> v(cellOf(p.x), cellOf(p.y), cellOf(p.z));
    lo_ = lo_.cwiseMin(v);
    hi_ = hi_.cwiseMax(v);
    const int64_t k = key(v.x(), v.y(), v.z());
    int c = cells_.find(k);
    if (c == BlockIndex::kMissing) {
      c = static_cast<int>(count.size());
      cells_.set(k, c);
      count.push_back(0);
    }
    ++count[c];
    cell_of[i] = c;
  }
  start_.assign(count.size() + 1, 0);
  for (size_t c = 0; c < count.size(); ++c) start_[c + 1] = start_[c] + count[c];
  std::vector<int> next(start_.begin(), start_.end() - 1);
  points_.resize(n);
  original_.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const int j = next[cell_of[i]]++;
    points_[j] = cloud[i].getVector3fMap();
    original_[j] = static_cast<int>(i);
  }
}

void PointGrid::visit(int64_t x, int64_t y, int64_t z, const Eigen::Vector3f& q, int k, float max_d2,
                      std::vector<int>& idx, std::vector<float>& d2) const {
  // A cell whose nearest corner is beyond the k-th best (or the radius) cannot contribute.
  auto gap = [this](int64_t c, float v) {
    const double lo = c * cell_;
    return v < lo ? lo - v : (v > lo + cell_ ? v - lo - cell_ : 0.0);
  };
  const double gx = gap(x, q.x()), gy = gap(y, q.y()), gz = gap(z, q.z());
  const double box2 = gx * gx + gy * gy + gz * gz;
  if (box2 >= max_d2 || (static_cast<int>(d2.size()) == k && box2 >= d2.back())) return;
  const int c = cells_.find(key(x, y, z));
  if (c == BlockIndex::kMissing) return;
  for (int j = start_[c]; j < start_[c + 1]; ++j) {
    const float d = (points_[j] - q).squaredNorm();
    const int n = static_cast<int>(d2.size());
    if (d >= max_d2 || (n == k && d >= d2.back())) continue;
    if (n < k) {
      d2.push_back(d);
      idx.push_back(original_[j]);
    }
    int i = static_cast<int>(d2.size()) - 1;
    for (; i > 0 && d2[i - 1] > d; --i) {
      d2[i] = d2[i - 1];
      idx[i] = idx[i - 1];
    }
    d2[i] = d;
    idx[i] = original_[j];
  }
}

void PointGrid::nearest(const Eigen::Vector3f& q, int k, float max_d2, std::vector<int>& idx,
                        std::vector<float>& d2) const {
  idx.clear();
  d2.clear();
  if (points_.empty() || k <= 0) return;
  const int64_t cx = cellOf(q.x()), cy = cellOf(q.y()), cz = cellOf(q.z());
  // Room between q and the faces of its own cell, per axis (lower, upper).
  const Eigen::Vector3d lo(q.x() - cx * cell_, q.y() - cy * cell_, q.z() - cz * cell_);
  const Eigen::Vector3d hi = Eigen::Vector3d::Constant(cell_) - lo;
  const double room = std::min(lo.minCoeff(), hi.minCoeff());
  for (int64_t s = 0;; ++s) {
    // Shell s: the cells at Chebyshev distance s from q's cell, inside the bounding box.
    const int64_t z0 = std::max(cz - s, lo_.z()), z1 = std::min(cz + s, hi_.z());
    const int64_t y0 = std::max(cy - s, lo_.y()), y1 = std::min(cy + s, hi_.y());
    const int64_t x0 = std::max(cx - s, lo_.x()), x1 = std::min(cx + s, hi_.x());
    for (int64_t z = z0; z <= z1; ++z)
      for (int64_t y = y0; y <= y1; ++y) {
        if (std::abs(z - cz) == s || std::abs(y - cy) == s) {
          for (int64_t x = x0; x <= x1; ++x) visit(x, y, z, q, k, max_d2, idx, d2);
        } else {
          if (cx - s >= lo_.x()) visit(cx - s, y, z, q, k, max_d2, idx, d2);
          if (s > 0 && cx + s <= hi_.x()) visit(cx + s, y, z, q, k, max_d2, idx, d2);
        }
      }
    // The shell cube holds every cell: nothing is left.
    if (cx - s <= lo_.x() && cy - s <= lo_.y() && cz - s <= lo_.z() && cx + s >= hi_.x() && cy + s >= hi_.y() &&
        cz + s >= hi_.z())
      return;
    // Every point not yet visited lies at least this far from q.
    const double reach = room + static_cast<double>(s) * cell_;
    const double reach2 = reach * reach;
    if (reach2 >= max_d2) return;
    if (static_cast<int>(d2.size()) == k && d2.back() <= reach2) return;
  }
}

}  // namespace dlslot::odometry
