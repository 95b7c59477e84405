#include "local_map.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace dlslot::odometry {

namespace {

int64_t floorDiv(int64_t a, int64_t b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

// floor(v) for the coordinates of a local map (|v| far below 2^62): std::floor is a library
// call without SSE4.1, this is a truncation and a compare.
int64_t floorToInt(float v) {
  const int64_t i = static_cast<int64_t>(v);
  return i - (v < static_cast<float>(i) ? 1 : 0);
}

}  // namespace

VoxelLayer::VoxelLayer(double voxel_m, double search_radius_m)
    : voxel_(voxel_m),
      m_(std::max(1, static_cast<int>(std::ceil(search_radius_m / voxel_m - 1e-9)))),
      radius2_(static_cast<float>(search_radius_m * search_radius_m)) {
  block_ = m_ * voxel_;
  capacity_ = m_ * m_ * m_;
}

int64_t VoxelLayer::blockKey(int64_t bx, int64_t by, int64_t bz) const {
  // 21 bits per axis: +-1e6 blocks, far beyond any local map.
  const int64_t off = int64_t{1} << 20;
  return ((bx + off) << 42) | ((by + off) << 21) | (bz + off);
}

void VoxelLayer::insert(const FeatureCloud& points, const Eigen::Isometry3f& T) {
  for (const auto& pt : points) {
    const Eigen::Vector3f p = T * pt.getVector3fMap();
    // The voxel grid of the kd-tree map this replaces: floor(v / voxel) in double.
    const int64_t vx = static_cast<int64_t>(std::floor(p.x() / voxel_));
    const int64_t vy = static_cast<int64_t>(std::floor(p.y() / voxel_));
    const int64_t vz = static_cast<int64_t>(std::floor(p.z() / voxel_));
    const int64_t bx = floorDiv(vx, m_), by = floorDiv(vy, m_), bz = floorDiv(vz, m_);
    const int slot = static_cast<int>(((vz - bz * m_) * m_ + (vy - by * m_)) * m_ + (vx - bx * m_));
    const int64_t key = blockKey(bx, by, bz);
    int b = index_.find(key);
    if (b == BlockIndex::kMissing) {
      b = static_cast<int>(blocks_.size());
      blocks_.push_back({key, bx, by, bz, 0});
      index_.set(key, b);
      means_.resize(blocks_.size() * capacity_);
      counts_.resize(blocks_.size() * capacity_);
      slots_.resize(blocks_.size() * capacity_);
    }
    Block& block = blocks_[b];
    const size_t base = static_cast<size_t>(b) * capacity_;
    int i = 0;
    while (i < block.n && slots_[base + i] != slot) ++i;
    if (i == block.n) {
      slots_[base + i] = slot;
      counts_[base + i] = 0;
      ++block.n;
      ++num_points_;
    }
    // A running mean averages the range noise of repeated observations of the same surface.
    Eigen::Vector3f& mean = means_[base + i];
    int& count = counts_[base + i];
    mean = count == 0 ? p : Eigen::Vector3f(mean + (p - mean) / static_cast<float>(count + 1));
    ++count;
  }
}

void VoxelLayer::removePoint(size_t b, int i) {
  const size_t base = b * capacity_;
  const int last = --blocks_[b].n;
  means_[base + i] = means_[base + last];
  counts_[base + i] = counts_[base + last];
  slots_[base + i] = slots_[base + last];
  --num_points_;
}

void VoxelLayer::removeBlock(size_t b) {
  num_points_ -= blocks_[b].n;
  index_.erase(blocks_[b].key);
  const size_t last = blocks_.size() - 1;
  if (b != last) {
    blocks_[b] = blocks_[last];
    std::copy_n(means_.begin() + last * capacity_, blocks_[b].n, means_.begin() + b * capacity_);
    std::copy_n(counts_.begin() + last * capacity_, blocks_[b].n, counts_.begin() + b * capacity_);
    std::copy_n(slots_.begin() + last * capacity_, blocks_[b].n, slots_.begin() + b * capacity_);
    index_.set(blocks_[b].key, static_cast<int>(b));
  }
  blocks_.pop_back();
}

void VoxelLayer::crop(const Eigen::Vector3d& center, double radius) {
  const float r2 = static_cast<float>(radius * radius);
  const Eigen::Vector2f c = center.head<2>().cast<float>();
  // Whole blocks are kept or dropped by their horizontal extent; only blocks the circle cuts
  // are decided voxel by voxel (with the same float test as per voxel, so the result is exact).
  const double margin = 1e-3;
  for (size_t b = blocks_.size(); b-- > 0;) {
    const Block& block = blocks_[b];
    const double x0 = block.bx * block_, y0 = block.by * block_;
    const double dx_near = std::max({x0 - center.x(), 0.0, center.x() - (x0 + block_)});
    const double dy_near = std::max({y0 - center.y(), 0.0, center.y() - (y0 + block_)});
    const double dx_far = std::max(std::abs(x0 - center.x()), std::abs(x0 + block_ - center.x()));
    const double dy_far = std::max(std::abs(y0 - center.y()), std::abs(y0 + block_ - center.y()));
    if (std::hypot(dx_far, dy_far) < radius - margin) continue;
    if (std::hypot(dx_near, dy_near) > radius + margin) {
      removeBlock(b);
      continue;
    }
    const size_t base = b * capacity_;
    for (int i = blocks_[b].n; i-- > 0;)
      if ((means_[base + i].head<2>() - c).squaredNorm() > r2) removePoint(b, i);
    if (blocks_[b].n == 0) removeBlock(b);
  }
}

void VoxelLayer::clear() {
  blocks_.clear();
  index_.clear();
  means_.clear();
  counts_.clear();
  slots_.clear();
  num_points_ = 0;
}

void VoxelLayer::nearest(const Eigen::Vector3f& q, int k, Neighbours& out) const {
  out.d2.clear();
  out.points.clear();
  if (blocks_.empty() || k <= 0) return;
  const double r = std::sqrt(static_cast<double>(radius2_));
  auto range = [&](float v, int64_t& lo, int64_t& hi) {
    lo = static_cast<int64_t>(std::floor((v - r) / block_));
    hi = static_cast<int64_t>(std::floor((v + r) / block_));
  };
  int64_t x0, x1, y0, y1, z0, z1;
  range(q.x(), x0, x1);
  range(q.y(), y0, y1);
  range(q.z(), z0, z1);
  // Per axis, the squared gap between q and each block of the range (at most 3 blocks: the
  // block edge is >= the radius): a block whose box lies beyond the radius, or beyond the k-th
  // best, is skipped before its lookup (the cube's corners mostly are).
  float gap2[3][3];
  const int64_t first[3] = {x0, y0, z0}, last[3] = {x1, y1, z1};
  for (int a = 0; a < 3; ++a)
    for (int64_t c = first[a]; c <= last[a]; ++c) {
      const double lo = c * block_, v = q[a];
      const double g = v < lo ? lo - v : (v > lo + block_ ? v - lo - block_ : 0.0);
      gap2[a][c - first[a]] = static_cast<float>(g * g);
    }
  // The k best so far, sorted, in the output's own storage (no push_back per candidate);
  // `worst` is the distance a candidate must beat: the radius until k are found, then the k-th.
  out.d2.resize(k);
  out.points.resize(k);
  float* best_d2 = out.d2.data();
  Eigen::Vector3f* best = out.points.data();
  int n = 0;
  float worst = radius2_;
  for (int64_t bz = z0; bz <= z1; ++bz)
    for (int64_t by = y0; by <= y1; ++by)
      for (int64_t bx = x0; bx <= x1; ++bx) {
        const float box2 = gap2[0][bx - x0] + gap2[1][by - y0] + gap2[2][bz - z0];
        if (box2 >= worst) continue;
        const int b = index_.find(blockKey(bx, by, bz));
        if (b == BlockIndex::kMissing) continue;
        const Eigen::Vector3f* p = means_.data() + static_cast<size_t>(b) * capacity_;
        const Eigen::Vector3f* end = p + blocks_[b].n;
        for (; p != end; ++p) {
          const float d2 = (*p - q).squaredNorm();
          if (d2 >= worst) continue;
          // Insertion into the sorted k best (the last one drops out when they are k).
          int j = n < k ? n++ : k - 1;
          for (; j > 0 && best_d2[j - 1] > d2; --j) {
            best_d2[j] = best_d2[j - 1];
            best[j] = best[j - 1];
          }
          best_d2[j] = d2;
          best[j] = *p;
          if (n == k) worst = best_d2[k - 1];
        }
      }
  out.d2.resize(n);
  out.points.resize(n);
}

std::vector<Eigen::Vector3f> VoxelLayer::points() const {
  std::vector<Eigen::Vector3f> out;
  out.reserve(num_points_);
  for (size_t b = 0; b < blocks_.size(); ++b)
    out.insert(out.end(), means_.begin() + b * capacity_, means_.begin() + b * capacity_ + blocks_[b].n);
  return out;
}

void LocalMap::insert(const FeatureCloud& edges, const FeatureCloud& planes, const Pose& T_world_lidar) {
  const Eigen::Isometry3f T = T_world_lidar.cast<float>();
  edges_.insert(edges, T);
  planes_.insert(planes, T);
  edges_.crop(T_world_lidar.translation(), radius_);
  planes_.crop(T_world_lidar.translation(), radius_);
}

void LocalMap::clear() {
  edges_.clear();
  planes_.clear();
}

FeatureCloud downsample(const FeatureCloud& cloud, double voxel_m) {
  // PCL's VoxelGrid filter (which this replaces: 5.5 % of the odometry's instructions, most of
  // it sorting every point by voxel) computed the same: voxels numbered x-fastest from the
  // cloud's smallest voxel, one centroid of x, y, z and intensity per occupied voxel, in voxel
  // order. Here the points are summed into their voxels through a hash, and only the occupied
  // voxels are sorted. (Sums run in point order, so a centroid may differ from PCL's in the
  // last bit.)
  FeatureCloud out;
  if (cloud.empty()) return out;
  const float inv = 1.0f / static_cast<float>(voxel_m);
  Eigen::Array3f lo = Eigen::Array3f::Constant(std::numeric_limits<float>::max()), hi = -lo;
  for (const auto& p : cloud) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) continue;
    lo = lo.min(p.getArray3fMap());
    hi = hi.max(p.getArray3fMap());
  }
  if (!(lo <= hi).all()) return out;
  const Eigen::Array3f min_b = (lo * inv).floor(), max_b = (hi * inv).floor();
  const Eigen::Array3f span = max_b - min_b + 1.0f;
  const int64_t nx = static_cast<int64_t>(span.x()), nxy = nx * static_cast<int64_t>(span.y());
  struct Sum {
    int64_t voxel;
    Eigen::Vector4f xyzi = Eigen::Vector4f::Zero();
    int n = 0;
  };
  std::vector<Sum> sums;
  BlockIndex index;
  int64_t last_voxel = -1;  // feature points come ring by ring: runs of them share a voxel
  int s = -1;
  for (const auto& p : cloud) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) continue;
    const int64_t ix = floorToInt(p.x * inv) - static_cast<int64_t>(min_b.x());
    const int64_t iy = floorToInt(p.y * inv) - static_cast<int64_t>(min_b.y());
    const int64_t iz = floorToInt(p.z * inv) - static_cast<int64_t>(min_b.z());
    const int64_t voxel = ix + iy * nx + iz * nxy;
    if (voxel != last_voxel) {
      last_voxel = voxel;
      s = index.find(voxel);
      if (s == BlockIndex::kMissing) {
        s = static_cast<int>(sums.size());
        index.set(voxel, s);
        sums.push_back({voxel});
      }
    }
    sums[s].xyzi += Eigen::Vector4f(p.x, p.y, p.z, p.intensity);
    ++sums[s].n;
  }
  std::sort(sums.begin(), sums.end(), [](const Sum& a, const Sum& b) { return a.voxel < b.voxel; });
  out.resize(sums.size());
  for (size_t i = 0; i < sums.size(); ++i) {
    const Eigen::Vector4f c = sums[i].xyzi / static_cast<float>(sums[i].n);
    out[i].x = c.x();
    out[i].y = c.y();
    out[i].z = c.z();
    out[i].intensity = c.w();
  }
  return out;
}

}  // namespace dlslot::odometry
