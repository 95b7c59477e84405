#include "grid.hpp"

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "drawing.hpp"
#include "palette.hpp"

namespace dlslot::renderer {

double gridStep(double metres_per_pixel, double min_px) {
  const double min_m = min_px * metres_per_pixel;
  double step = std::pow(10.0, std::floor(std::log10(min_m)));
  while (step < min_m) {
    for (double m : {1.0, 2.0, 5.0})
      if (m * step >= min_m) return m * step;
    step *= 10.0;
  }
  return step;
}

void rangeRings(cv::Mat& img, const Eigen::Vector2d& centre_px, double metres_per_pixel) {
  const double step = gridStep(metres_per_pixel, 90.0);
  const double max_r = std::hypot(img.cols, img.rows) * metres_per_pixel;
  // Faint forward and lateral axes through the ego.
  line(img, Eigen::Vector2d(centre_px.x(), 0), Eigen::Vector2d(centre_px.x(), img.rows), colour::kGrid, 1);
  line(img, Eigen::Vector2d(0, centre_px.y()), Eigen::Vector2d(img.cols, centre_px.y()), colour::kGrid, 1);
  for (double r = step; r < max_r; r += step) {
    const int r_px = static_cast<int>(std::lround(r / metres_per_pixel * (1 << kShift)));
    cv::circle(img, subpixel(centre_px), r_px, colour::kGridMajor, 1, cv::LINE_AA, kShift);
    // Distance label where the ring crosses the diagonal to the upper right.
    const double a = r / metres_per_pixel / std::sqrt(2.0);
    text(img, strf("%g m", r), cv::Point(static_cast<int>(centre_px.x() + a) + 3, static_cast<int>(centre_px.y() - a) - 3),
         colour::kTextDim, 0.38);
  }
}

void worldGrid(cv::Mat& img, const ViewTransform& view) {
  const ViewTransform::Projection& P = view.worldToPixel();
  const double step = gridStep(view.metresPerPixel(), 60.0);
  // World x at pixel u and world y at pixel v, the view being axis-aligned.
  const double x0 = (0 - P(0, 3)) / P(0, 0), x1 = (img.cols - P(0, 3)) / P(0, 0);
  const double y0 = (img.rows - P(1, 3)) / P(1, 1), y1 = (0 - P(1, 3)) / P(1, 1);
  for (double x = std::ceil(x0 / step) * step; x <= x1; x += step) {
    const bool major = std::fmod(std::abs(std::round(x / step)), 5.0) == 0.0;
    const double u = P(0, 0) * x + P(0, 3);
    line(img, Eigen::Vector2d(u, 0), Eigen::Vector2d(u, img.rows), major ? colour::kGridMajor : colour::kGrid, 1);
    if (major) text(img, strf("x %g", x), cv::Point(static_cast<int>(u) + 3, img.rows - 64), colour::kTextDim, 0.38);
  }
  for (double y = std::ceil(y0 / step) * step; y <= y1; y += step) {
    const bool major = std::fmod(std::abs(std::round(y / step)), 5.0) == 0.0;
    const double v = P(1, 1) * y + P(1, 3);
    line(img, Eigen::Vector2d(0, v), Eigen::Vector2d(img.cols, v), major ? colour::kGridMajor : colour::kGrid, 1);
    if (major) text(img, strf("y %g", y), cv::Point(img.cols - 60, static_cast<int>(v) - 3), colour::kTextDim, 0.38);
  }
}

}  // namespace dlslot::renderer
