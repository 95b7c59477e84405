#include "view_transform.hpp"

#include <cmath>

namespace dlslot::renderer {
namespace {

// Pixel from a planar frame whose origin is at the image centre: +x up and +y left (heading up,
// like looking down from above the vehicle) or +x right and +y up (map convention).
Eigen::Matrix<double, 2, 4> planarToPixel(double mpp, int width, int height, bool x_up) {
  Eigen::Matrix<double, 2, 4> P = Eigen::Matrix<double, 2, 4>::Zero();
  const double k = 1.0 / mpp;
  if (x_up) {
    P(0, 1) = -k;  // u grows to the right = -y
    P(1, 0) = -k;  // v grows downwards = -x
  } else {
    P(0, 0) = k;
    P(1, 1) = -k;
  }
  P(0, 3) = 0.5 * width;
  P(1, 3) = 0.5 * height;
  return P;
}

}  // namespace

ViewTransform ViewTransform::forFrame(const ViewConfig& view, const std::optional<Pose>& T_world_lidar) {
  const Pose T_wl = T_world_lidar.value_or(Pose::Identity());
  ViewTransform v;
  v.metres_per_pixel_ = view.metres_per_pixel;
  if (view.mode == ViewConfig::Mode::World) {
    v = worldWindow(view.world_center, view.metres_per_pixel, view.width, view.height);
    v.pix_lidar_ = v.pix_world_ * T_wl.matrix();
  } else if (view.heading_up) {
    // The scan is drawn as measured (lidar frame), world layers are brought into it.
    v.pix_lidar_ = planarToPixel(view.metres_per_pixel, view.width, view.height, true);
    v.pix_world_ = v.pix_lidar_ * T_wl.inverse().matrix();
  } else {
    Pose T_centre = Pose::Identity();
    T_centre.translation() = T_wl.translation();
    v.pix_world_ = planarToPixel(view.metres_per_pixel, view.width, view.height, false) * T_centre.inverse().matrix();
    v.pix_lidar_ = v.pix_world_ * T_wl.matrix();
  }
  return v;
}

ViewTransform ViewTransform::worldWindow(const Eigen::Vector2d& centre, double metres_per_pixel, int width,
                                         int height) {
  ViewTransform v;
  v.metres_per_pixel_ = metres_per_pixel;
  Pose T_centre = Pose::Identity();
  T_centre.translation() = Eigen::Vector3d(centre.x(), centre.y(), 0.0);
  v.pix_world_ = planarToPixel(metres_per_pixel, width, height, false) * T_centre.inverse().matrix();
  v.pix_lidar_ = v.pix_world_;
  return v;
}

}  // namespace dlslot::renderer
