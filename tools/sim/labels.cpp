#include "labels.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "calib.hpp"

namespace dlslot::sim {

std::optional<ImageBox> projectToImage(const Box& box, const kitti::Calib& calib) {
  const Pose T_rect_box = calib.T_rect_velo() * box.pose();
  std::array<Eigen::Vector3d, 8> corners;
  for (int i = 0; i < 8; ++i)
    corners[i] = T_rect_box * Eigen::Vector3d((i & 1 ? 0.5 : -0.5) * box.size.x(), (i & 2 ? 0.5 : -0.5) * box.size.y(),
                                              (i & 4 ? 0.5 : -0.5) * box.size.z());
  // Clip the 12 edges at a near plane in front of the camera, project what is left.
  constexpr double kNear = 0.1;
  std::vector<Eigen::Vector3d> visible;
  for (int i = 0; i < 8; ++i) {
    if (corners[i].z() >= kNear) visible.push_back(corners[i]);
    for (int bit : {1, 2, 4}) {
      const int j = i | bit;
      if (j == i) continue;
      const Eigen::Vector3d &a = corners[i], &b = corners[j];
      if ((a.z() - kNear) * (b.z() - kNear) < 0) visible.push_back(a + (kNear - a.z()) / (b.z() - a.z()) * (b - a));
    }
  }
  if (visible.empty()) return std::nullopt;
  double l = 1e300, t = 1e300, r = -1e300, bo = -1e300;
  for (const Eigen::Vector3d& p : visible) {
    const Eigen::Vector3d uvw = calib.P[2] * p.homogeneous();
    const double u = uvw.x() / uvw.z(), v = uvw.y() / uvw.z();
    l = std::min(l, u);
    r = std::max(r, u);
    t = std::min(t, v);
    bo = std::max(bo, v);
  }
  const double area = (r - l) * (bo - t);
  ImageBox ib;
  ib.bbox << std::clamp(l, 0.0, kImageWidth - 1), std::clamp(t, 0.0, kImageHeight - 1),
      std::clamp(r, 0.0, kImageWidth - 1), std::clamp(bo, 0.0, kImageHeight - 1);
  const double clipped = (ib.bbox[2] - ib.bbox[0]) * (ib.bbox[3] - ib.bbox[1]);
  if (clipped <= 0) return std::nullopt;
  ib.truncated = area > 0 ? std::clamp(1.0 - clipped / area, 0.0, 1.0) : 0.0;
  return ib;
}

int occlusionLevel(const ObjectView& view) {
  if (view.rays == 0) return 3;
  const double f = static_cast<double>(view.blocked) / view.rays;
  return f < 0.1 ? 0 : f < 0.5 ? 1 : 2;
}

kitti::LabelRow labelRow(int frame, int track_id, const std::string& type, const Box& box_lidar,
                         const kitti::Calib& calib, int occluded) {
  kitti::LabelRow row;
  row.frame = frame;
  row.track_id = track_id;
  row.type = type;
  row.box = kitti::lidarToCamera(box_lidar, calib);
  row.occluded = occluded;
  // alpha: the observation angle, rotation_y minus the direction to the object.
  row.alpha = wrapAngle(row.box.rotation_y - std::atan2(row.box.bottom_center.x(), row.box.bottom_center.z()));
  if (const auto ib = projectToImage(box_lidar, calib)) {
    row.bbox2d = ib->bbox;
    row.truncated = ib->truncated;
  } else {
    row.bbox2d = Eigen::Vector4d::Constant(-1.0);
    row.truncated = 1.0;  // entirely outside the image
  }
  return row;
}

}  // namespace dlslot::sim
