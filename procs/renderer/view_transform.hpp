// Metric coordinates -> image pixels for one image: a 2x4 matrix per source frame, so a point
// costs one small matrix product whether it is given in the lidar or the world frame.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <opencv2/core.hpp>

#include "dlslot/types.hpp"
#include "render_config.hpp"

namespace dlslot::renderer {

class ViewTransform {
 public:
  using Projection = Eigen::Matrix<double, 2, 4>;  // [u v] = P * [x y z 1]

  // The per-frame view: centred on the ego (heading up or world-aligned) or a fixed world window.
  // Without an ego pose the lidar frame is taken as the world frame.
  static ViewTransform forFrame(const ViewConfig& view, const std::optional<Pose>& T_world_lidar);
  // A world-aligned window (x right, y up) centred on `centre`.
  static ViewTransform worldWindow(const Eigen::Vector2d& centre, double metres_per_pixel, int width, int height);

  const Projection& lidarToPixel() const { return pix_lidar_; }
  const Projection& worldToPixel() const { return pix_world_; }
  Eigen::Vector2d fromLidar(const Eigen::Vector3d& p) const { return pix_lidar_ * p.homogeneous(); }
  Eigen::Vector2d fromWorld(const Eigen::Vector3d& p) const { return pix_world_ * p.homogeneous(); }
  double metresPerPixel() const { return metres_per_pixel_; }

 private:
  Projection pix_lidar_, pix_world_;
  double metres_per_pixel_ = 1.0;
};

// Sub-pixel point for OpenCV drawing with `kShift` fractional bits (smooth anti-aliased lines).
constexpr int kShift = 4;
inline cv::Point subpixel(const Eigen::Vector2d& p) {
  return cv::Point(static_cast<int>(std::lround(p.x() * (1 << kShift))),
                   static_cast<int>(std::lround(p.y() * (1 << kShift))));
}

}  // namespace dlslot::renderer
