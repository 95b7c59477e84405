// The objects' classes: realistic sizes (KITTI label statistics) and solid shapes in the labelled
// box: a vehicle's body stands on wheels in arches, and only its mirrors reach out of the box, as
// KITTI's boxes leave them out.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "rng.hpp"
#include "solid.hpp"

namespace dlslot::sim {

// How far an object's parts reach outside its labelled box (a truck's mirrors), metres.
constexpr double kPartsOutsideBoxM = 0.25;

// Box size (l, w, h) of a random member of the class ("Car", "Van", "Truck", "Cyclist", "Pedestrian").
Eigen::Vector3d sampleSize(const std::string& type, Rng& rng);
// The solids of an object of that class and size, in the box's own frame (origin at the box
// centre, x forward, z up); `reflectivity` is the paint or clothing.
std::vector<Solid> objectParts(const std::string& type, const Eigen::Vector3d& size, float reflectivity);
bool isVehicle(const std::string& type);  // Car, Van, Truck

}  // namespace dlslot::sim
