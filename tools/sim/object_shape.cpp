#include "object_shape.hpp"

#include <algorithm>
#include <stdexcept>

namespace dlslot::sim {
namespace {

double clampedNormal(Rng& rng, double mean, double sigma, double lo, double hi) {
  return std::clamp(rng.normal(mean, sigma), lo, hi);
}

// A box part spanning x0..x1 along the object, width w, z0..z1 above the object's bottom.
Solid part(double x0, double x1, double w, double z0, double z1, double bottom, float refl) {
  return Solid::box(Eigen::Vector3d(0.5 * (x0 + x1), 0.0, bottom + 0.5 * (z0 + z1)),
                    Eigen::Vector3d(x1 - x0, w, z1 - z0), 0.0, refl);
}

}  // namespace

bool isVehicle(const std::string& type) { return type == "Car" || type == "Van" || type == "Truck"; }

Eigen::Vector3d sampleSize(const std::string& type, Rng& rng) {
  if (type == "Car")
    return {clampedNormal(rng, 4.2, 0.3, 3.5, 5.0), clampedNormal(rng, 1.72, 0.08, 1.5, 1.95),
            clampedNormal(rng, 1.5, 0.08, 1.35, 1.75)};
  if (type == "Van") return {rng.uniform(4.6, 5.6), rng.uniform(1.85, 2.05), rng.uniform(1.9, 2.5)};
  if (type == "Truck") return {rng.uniform(7.0, 12.0), rng.uniform(2.4, 2.55), rng.uniform(3.0, 3.8)};
  if (type == "Cyclist") return {rng.uniform(1.6, 1.9), rng.uniform(0.55, 0.75), rng.uniform(1.6, 1.85)};
  if (type == "Pedestrian") return {rng.uniform(0.6, 0.95), rng.uniform(0.5, 0.7), rng.uniform(1.55, 1.9)};
  throw std::invalid_argument("unknown object class '" + type + "'");
}

std::vector<Solid> objectParts(const std::string& type, const Eigen::Vector3d& size, float refl) {
  const double l = size.x(), w = size.y(), h = size.z(), bottom = -0.5 * h;
  const float glass = 0.5f * refl;  // windows return weaker
  if (type == "Car")                // body to 58 % of the height, a shorter and narrower cabin on top
    return {part(-0.5 * l, 0.5 * l, w, 0.15, 0.58 * h, bottom, refl),
            part(-0.36 * l, 0.2 * l, 0.9 * w, 0.58 * h, h, bottom, glass)};
  if (type == "Van")
    return {part(-0.5 * l, 0.5 * l, w, 0.15, 0.62 * h, bottom, refl),
            part(-0.5 * l, 0.36 * l, 0.97 * w, 0.62 * h, h, bottom, glass)};
  if (type == "Truck")  // chassis, cab in front, cargo box behind
    return {part(-0.5 * l, 0.5 * l, 0.9 * w, 0.4, 1.0, bottom, 0.3f),
            part(0.5 * l - 2.3, 0.5 * l, w, 0.4, 0.85 * h, bottom, refl),
            part(-0.5 * l, 0.5 * l - 2.5, w, 1.0, h, bottom, 0.6f)};
  if (type == "Cyclist") {  // the bicycle, the rider's body and head
    Solid body =
        Solid::cylinder(Eigen::Vector2d(-0.1, 0.0), bottom + 0.9, bottom + h - 0.25, std::min(0.2, 0.45 * w), refl);
    return {part(-0.5 * l, 0.5 * l, 0.12, 0.05, 1.0, bottom, 0.35f), body,
            Solid::sphere(Eigen::Vector3d(-0.05, 0.0, bottom + h - 0.13), 0.12, refl)};
  }
  if (type == "Pedestrian") {
    const double r = 0.4 * std::min(l, w);
    return {Solid::cylinder(Eigen::Vector2d::Zero(), bottom, bottom + h - 0.24, r, refl),
            Solid::sphere(Eigen::Vector3d(0.0, 0.0, bottom + h - 0.12), 0.11, refl)};
  }
  throw std::invalid_argument("unknown object class '" + type + "'");
}

}  // namespace dlslot::sim
