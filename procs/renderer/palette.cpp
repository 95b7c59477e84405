#include "palette.hpp"

#include <cmath>

namespace dlslot::renderer {
namespace {

// Piecewise-linear through three stops (BGR), t in [0, 1].
cv::Vec3b ramp(const cv::Vec3b (&stops)[3], double t) {
  const cv::Vec3b& a = t < 0.5 ? stops[0] : stops[1];
  const cv::Vec3b& b = t < 0.5 ? stops[1] : stops[2];
  const double u = t < 0.5 ? 2.0 * t : 2.0 * t - 1.0;
  cv::Vec3b out;
  for (int c = 0; c < 3; ++c) out[c] = static_cast<uchar>(std::lround(a[c] + u * (b[c] - a[c])));
  return out;
}

}  // namespace

PointShading::PointShading(double min_z, double max_z)
    : min_z_(static_cast<float>(min_z)), scale_(static_cast<float>(126.999 / (max_z - min_z))) {
  // Ground dim, mid-height brighter, tall structure near white; removed: red -> orange -> amber.
  const cv::Vec3b kept[3] = {{92, 72, 62}, {170, 148, 126}, {245, 240, 232}};
  const cv::Vec3b removed[3] = {{50, 45, 190}, {45, 105, 245}, {120, 200, 255}};
  lut_[0] = cv::Vec3b(0, 0, 0);
  for (int i = 0; i < 127; ++i) {
    lut_[1 + i] = ramp(kept, i / 126.0);
    lut_[128 + i] = ramp(removed, i / 126.0);
  }
  lut_[255] = lut_[254];
}

cv::Scalar trackColour(int id) {
  if (id < 0) return cv::Scalar(160, 160, 160);
  // Golden-ratio steps through the hues that no fixed overlay uses (reds, oranges, blues,
  // violets, pinks; not the green / magenta / cyan trajectories or the yellow detections), so
  // neighbouring ids differ and a track is never mistaken for a trajectory.
  const double allowed[3][2] = {{0.0, 45.0}, {200.0, 280.0}, {325.0, 360.0}};
  double u = std::fmod(0.05 + id * 0.618033988749895, 1.0) * 160.0;  // 160 = total allowed degrees
  double hue = 0.0;
  for (const auto& range : allowed) {
    if (u <= range[1] - range[0]) {
      hue = range[0] + u;
      break;
    }
    u -= range[1] - range[0];
  }
  // HSV -> BGR; every other id slightly darker and more saturated for extra separation.
  const double h = hue / 60.0, s = id % 2 ? 0.75 : 0.55, v = id % 2 ? 235.0 : 255.0;
  const int sector = static_cast<int>(h) % 6;
  const double f = h - std::floor(h);
  const double p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
  double r, g, b;
  switch (sector) {
    case 0: r = v, g = t, b = p; break;
    case 1: r = q, g = v, b = p; break;
    case 2: r = p, g = v, b = t; break;
    case 3: r = p, g = q, b = v; break;
    case 4: r = t, g = p, b = v; break;
    default: r = v, g = p, b = q; break;
  }
  return cv::Scalar(std::round(b), std::round(g), std::round(r));
}

cv::Scalar dimmed(const cv::Scalar& c, double factor) {
  return cv::Scalar(std::round(c[0] * factor), std::round(c[1] * factor), std::round(c[2] * factor));
}

}  // namespace dlslot::renderer
