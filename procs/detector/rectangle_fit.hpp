// The oriented bird's-eye rectangle of a cluster: the search-based L-shape fit of Zhang et al.
// ("Efficient L-shape fitting for vehicle detection using laser scanners", IV 2017) with its
// closeness criterion. A lidar sees one or two sides of a vehicle; for each heading the points
// are projected on the two axes and score by how close each lies to its nearest rectangle edge,
// so the heading that puts the seen sides on edges wins. Searched coarse to fine over [0, 90).
#pragma once

#include <Eigen/Core>
#include <vector>

namespace dlslot::detector {

struct Rectangle {
  Eigen::Vector2d center = Eigen::Vector2d::Zero();
  double length = 0, width = 0;  // along yaw, across it; length >= width
  double yaw = 0;                // heading of the length axis, in (-pi/2, pi/2]
  double edge_fraction = 0;      // share of the points within edge_band_m of an edge
};

// The best rectangle around `points` (xy, at least one). edge_band_m: what counts as on an edge.
Rectangle fitRectangle(const std::vector<Eigen::Vector2f>& points, double edge_band_m = 0.2);

}  // namespace dlslot::detector
