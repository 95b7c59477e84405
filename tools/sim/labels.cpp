#include "labels.hpp"

#include <algorithm>
#include <cmath>

#include "calib.hpp"

namespace dlslot::sim {

std::optional<ImageBox> projectToImage(const Box& box, const kitti::Calib& calib) {
  // The label row's own 3-D box (upright in the camera frame) projected, as a reader of the row would.
  const auto ib = kitti::projectToImage(kitti::lidarToCamera(box, calib), calib, {kImageWidth, kImageHeight});
  if (!ib) return std::nullopt;
  const auto area = [](const Eigen::Vector4d& b) { return (b[2] - b[0]) * (b[3] - b[1]); };
  return ImageBox{ib->bbox2d, area(ib->unclipped) > 0 ? std::clamp(1.0 - area(ib->bbox2d) / area(ib->unclipped), 0.0, 1.0) : 0.0};
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
  row.alpha = kitti::observationAngle(row.box);
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
