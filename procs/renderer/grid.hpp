// Metric reference drawn under everything: range rings around the ego (heading-up view) or a
// world-aligned grid with coordinates (world-aligned views and the summary).
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "view_transform.hpp"

namespace dlslot::renderer {

// The smallest round spacing (1, 2 or 5 x 10^k m) at least min_px pixels apart.
double gridStep(double metres_per_pixel, double min_px);

void rangeRings(cv::Mat& img, const Eigen::Vector2d& centre_px, double metres_per_pixel);
// The view must be world-aligned (x right, y up), as in world mode and the summary.
void worldGrid(cv::Mat& img, const ViewTransform& view);

}  // namespace dlslot::renderer
