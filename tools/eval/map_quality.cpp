#include "map_quality.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <unordered_map>
#include <unordered_set>

#include "dlslot/voxel_key.hpp"

namespace dlslot::eval {

std::set<int> movingTracks(const std::map<int, std::vector<Box>>& labels_by_frame, const std::map<int, Pose>& poses,
                           double moving_span_m) {
  std::map<int, std::vector<Eigen::Vector3d>> centres;
  for (const auto& [frame, boxes] : labels_by_frame) {
    const auto T = poses.find(frame);
    if (T == poses.end()) continue;
    for (const Box& b : boxes)
      if (b.id >= 0) centres[b.id].push_back(T->second * b.center);
  }
  std::set<int> moving;
  for (const auto& [id, c] : centres) {
    double span = 0;
    for (size_t i = 0; i < c.size() && span <= moving_span_m; ++i)
      for (size_t j = i + 1; j < c.size(); ++j) span = std::max(span, (c[i] - c[j]).head<2>().norm());
    if (span > moving_span_m) moving.insert(id);
  }
  return moving;
}

std::vector<MovingBox> movingLabels(const std::map<int, std::vector<Box>>& labels_by_frame, int frame, double dt) {
  std::vector<MovingBox> out;
  const auto here = labels_by_frame.find(frame);
  if (here == labels_by_frame.end()) return out;
  const auto find = [&](int f, int id) -> const Box* {
    const auto it = labels_by_frame.find(f);
    if (it == labels_by_frame.end() || id < 0) return nullptr;
    for (const Box& b : it->second)
      if (b.id == id) return &b;
    return nullptr;
  };
  for (const Box& b : here->second) {
    const Box* before = find(frame - 1, b.id);
    const Box* after = find(frame + 1, b.id);
    const Box& a = before ? *before : b;
    const Box& c = after ? *after : b;
    const int steps = (before ? 1 : 0) + (after ? 1 : 0);
    out.push_back(steps ? movingBox(b, a, c, steps * dt) : MovingBox{b});
  }
  return out;
}

MapScore scoreMap(const PointCloud& map_points, const std::vector<MapKeyframe>& keyframes, const std::set<int>& moving,
                  const MapTruthOptions& o) {
  if (!(o.coincidence_m > 0 && o.coincidence_m < 0.5 * o.voxel_m))
    throw std::invalid_argument("scoreMap: coincidence_m must lie in (0, voxel_m / 2)");
  MapScore s;
  s.voxel_m = o.voxel_m;
  // The map's points by voxel of the map's (final) placement, to find them among the truth's.
  std::unordered_map<uint64_t, std::vector<Eigen::Vector3d>> map_cells;
  map_cells.reserve(map_points.cols());
  for (Eigen::Index i = 0; i < map_points.cols(); ++i) {
    const Eigen::Vector3d m = map_points.col(i).head<3>().cast<double>();
    map_cells[voxelKey(m, o.voxel_m)].push_back(m);
  }
  const double e = o.coincidence_m, e2 = e * e;
  // Whether q (a truth point where the map's poses put it) is one of the map's points: the cells
  // the cube of half-side e around q touches (one, or two by an axis near a cell's face).
  const auto inMap = [&](const Eigen::Vector3d& q) {
    const Eigen::Vector3d lo_cell = ((q.array() - e) / o.voxel_m).floor(), hi_cell = ((q.array() + e) / o.voxel_m).floor();
    for (double x = lo_cell.x(); x <= hi_cell.x(); ++x)
      for (double y = lo_cell.y(); y <= hi_cell.y(); ++y)
        for (double z = lo_cell.z(); z <= hi_cell.z(); ++z) {
          const auto it = map_cells.find(voxelKey((Eigen::Vector3d(x, y, z).array() + 0.5) * o.voxel_m, o.voxel_m));
          if (it == map_cells.end()) continue;
          for (const Eigen::Vector3d& m : it->second)
            if ((m - q).squaredNorm() <= e2) return true;
        }
    return false;
  };
  struct Votes {
    int static_points = 0, dynamic_points = 0;
  };
  std::unordered_map<uint64_t, Votes> votes;
  std::unordered_set<uint64_t> held;  // grid voxels one of whose points is in the map
  const double lo = o.min_range_m * o.min_range_m, hi = o.max_range_m * o.max_range_m;
  for (const MapKeyframe& kf : keyframes) {
    const Pose& T_grid = kf.T_grid_lidar ? *kf.T_grid_lidar : kf.T_map_lidar;
    std::vector<const MovingBox*> boxes;
    for (const MovingBox& b : kf.labels)
      if (moving.count(b.box.id)) boxes.push_back(&b);
    for (Eigen::Index i = 0; i < kf.scan.cols(); ++i) {
      const Eigen::Vector3d p = kf.scan.col(i).head<3>().cast<double>();
      const double d2 = p.squaredNorm();
      if (d2 < lo || d2 > hi) continue;
      // Whether the voxel is held is asked of every point the mapper looked at, scored or not
      // (a voxel's map point may be one outside the camera's view or in a DontCare box).
      const uint64_t key = voxelKey(T_grid * p, o.voxel_m);
      if (!held.count(key) && inMap(kf.T_map_lidar * p)) held.insert(key);
      if (o.T_cam_lidar) {
        const Eigen::Vector3d c = *o.T_cam_lidar * p;  // camera: z forward, x right
        if (c.z() <= 0 || std::abs(std::atan2(c.x(), c.z())) > o.camera_half_fov_rad) continue;
      }
      bool unlabelled = false;
      for (const Box& b : kf.dontcare) unlabelled = unlabelled || b.contains(p);
      if (unlabelled) continue;
      bool dynamic = false, band = false;
      const double t = boxes.empty() ? 0.0 : o.sweep.firingTime(p.x(), p.y());
      for (const MovingBox* m : boxes) {
        Box b = m->at(t);
        b.size += Eigen::Vector3d(2 * o.label_tolerance_m, 2 * o.label_tolerance_m, o.label_tolerance_m);
        b.center.z() += 0.5 * o.label_tolerance_m;
        if (b.contains(p)) {
          dynamic = true;
          band = band || p.z() < b.center.z() - 0.5 * b.size.z() + o.bottom_band_m;
        }
      }
      if (band) continue;
      Votes& v = votes[key];
      (dynamic ? v.dynamic_points : v.static_points) += 1;
    }
  }
  for (const auto& [key, v] : votes) {
    const bool kept = held.count(key) > 0;
    if (v.dynamic_points > v.static_points) {
      ++s.dynamic_voxels;
      s.dynamic_removed += !kept;
    } else {
      ++s.static_voxels;
      s.static_kept += kept;
    }
  }
  if (s.static_voxels) s.sa = double(s.static_kept) / s.static_voxels;
  if (s.dynamic_voxels) s.da = double(s.dynamic_removed) / s.dynamic_voxels;
  if (s.sa && s.da) s.aa = std::sqrt(*s.sa * *s.da);
  return s;
}

bool isFalseLoop(const Pose& measured, const Pose& truth, double max_m, double max_deg) {
  const Pose e = truth.inverse() * measured;
  return e.translation().norm() > max_m || Eigen::AngleAxisd(e.rotation()).angle() * 180.0 / M_PI > max_deg;
}

}  // namespace dlslot::eval
