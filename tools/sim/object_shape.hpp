// The objects' classes: realistic sizes (KITTI label statistics) and solid shapes inside the
// labelled box, so the box a label gives is the box the points come from.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "rng.hpp"
#include "solid.hpp"

namespace dlslot::sim {

// Box size (l, w, h) of a random member of the class ("Car", "Van", "Truck", "Cyclist", "Pedestrian").
Eigen::Vector3d sampleSize(const std::string& type, Rng& rng);
// The solids of an object of that class and size, in the box's own frame (origin at the box
// centre, x forward, z up); `reflectivity` is the paint or clothing.
std::vector<Solid> objectParts(const std::string& type, const Eigen::Vector3d& size, float reflectivity);
bool isVehicle(const std::string& type);  // Car, Van, Truck

}  // namespace dlslot::sim
