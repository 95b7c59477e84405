// Overlap of oriented boxes for the IoU-based tracking metrics: the exact intersection of the two
// bird's-eye-view rectangles (convex polygon clipping) times the overlap of their height ranges.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "dlslot/types.hpp"

namespace dlslot::eval {

// The box's footprint in the xy plane: four corners, counter-clockwise.
std::vector<Eigen::Vector2d> footprint(const Box& box);
// Area of the intersection of two convex counter-clockwise polygons.
double convexIntersectionArea(const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b);
double bevIntersectionArea(const Box& a, const Box& b);
// Volume IoU of two upright oriented boxes (0 when either has no volume).
double iou3d(const Box& a, const Box& b);
// Distance of the box centres in the xy plane.
double bevDistance(const Box& a, const Box& b);
// True when p lies inside the box's footprint (height ignored).
bool footprintContains(const Box& box, const Eigen::Vector3d& p);

}  // namespace dlslot::eval
