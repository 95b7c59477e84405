#include "backend/object_model.hpp"

#include <algorithm>
#include <cmath>

namespace dlslot::backend {

void ObjectModel::update(const ObjectPoints& scan, int frame, const std::optional<Pose>& motion, double range,
                         const RegistrationOptions& o) {
  ObjectPoints merged(scan);
  std::vector<int> frames(scan.size(), frame);
  // The older points, carried to this scan by the measured motion; those beyond the model's span dropped.
  if (motion && frame_ == frame - 1) {
    const Eigen::Matrix3f R = motion->linear().cast<float>();
    const Eigen::Vector3f t = motion->translation().cast<float>();
    for (size_t i = 0; i < points_.size(); ++i) {
      if (frame - frames_[i] >= o.model_frames) continue;
      merged.push_back(R * points_[i] + t);
      frames.push_back(frames_[i]);
    }
  }
  // The registration's target spacing (PreparedObject: half its voxel); the newest first, so each
  // cell keeps this scan's point and the cap drops the oldest.
  // Thinned only past the cap: a far object's few points all stay (its count is what
  // min_points judges).
  std::vector<int> kept(merged.size());
  for (size_t i = 0; i < kept.size(); ++i) kept[i] = static_cast<int>(i);
  if (static_cast<int>(merged.size()) > o.max_model_points) {
    const double voxel = std::max(o.min_voxel, o.voxel_per_m * range);
    kept = thinIndices(merged, 0.5 * voxel, static_cast<int>(merged.size()));
    if (static_cast<int>(kept.size()) > o.max_model_points) kept.resize(static_cast<size_t>(o.max_model_points));
  }
  points_.clear();
  frames_.clear();
  points_.reserve(kept.size());
  frames_.reserve(kept.size());
  for (int i : kept) {
    points_.push_back(merged[static_cast<size_t>(i)]);
    frames_.push_back(frames[static_cast<size_t>(i)]);
  }
  frame_ = frame;
}

int ObjectModel::scans() const {
  if (frames_.empty()) return 0;
  const auto [lo, hi] = std::minmax_element(frames_.begin(), frames_.end());
  return *hi - *lo + 1;
}

RefinedBox refinedBox(const Pose& box, const Eigen::Vector3d& size, const ObjectPoints& points,
                      const Eigen::Vector3d& sensor, int min_points, double trim) {
  RefinedBox out{box, size};
  if (static_cast<int>(points.size()) < std::max(min_points, 1)) return out;
  const Pose inv = box.inverse();
  const Eigen::Vector3d s = inv * sensor;
  std::vector<double> u[2];
  for (const Eigen::Vector3f& p : points) {
    const Eigen::Vector3d q = inv * p.cast<double>();
    u[0].push_back(q.x());
    u[1].push_back(q.y());
  }
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();
  // The sensor looks at an end of axis a squarely (it is within the box's span across a): that end
  // is in view whole. Seen at an angle, the points may hold only the side, and where they stop
  // says nothing about where the end is.
  const auto end_on = [&](int a) { return std::abs(s[1 - a]) < 0.5 * size[1 - a]; };
  const size_t n = points.size();
  const size_t k = static_cast<size_t>(std::floor(trim * static_cast<double>(n)));
  for (int a = 0; a < 2; ++a) {
    std::nth_element(u[a].begin(), u[a].begin() + static_cast<long>(k), u[a].end());
    const double lo = u[a][k];
    std::nth_element(u[a].begin(), u[a].begin() + static_cast<long>(n - 1 - k), u[a].end());
    const double hi = u[a][n - 1 - k];
    const double half = 0.5 * size[a];
    if (hi - lo >= size[a]) {
      // Seen end to end: the points' extent is the size.
      out.size[a] = hi - lo;
      shift[a] = 0.5 * (lo + hi);
    } else if (end_on(a) && s[a] < lo) {
      shift[a] = lo + half;  // the near end seen, the far one not
    } else if (end_on(a) && s[a] > hi) {
      shift[a] = hi - half;
    } else {
      shift[a] = std::clamp(0.0, hi - half, lo + half);
    }
  }
  out.pose.translation() = box * shift;
  return out;
}

}  // namespace dlslot::backend
