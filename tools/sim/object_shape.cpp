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

// A vehicle's running gear: tyres of this radius and width on axles at these positions along
// it, their outer faces `inset` inside the body's sides (width w).
struct Wheels {
  double radius, width, inset;
  std::vector<double> axles;
  double archHalf() const { return radius + 0.06; }  // an arch clears the tyre by a hand's breadth
  double archTop() const { return 2 * radius + 0.06; }
};

// The body's sides from z0 to z1 over x0..x1 with an arch cut out over each axle up to above the
// tyre, and behind each arch the wheel well's inner wall, well_width across (0: none). Without
// the arches a lidar sees a car as a box on stilts; with them its lower sides break up where the
// wheels turn, as real cars' do.
void bodyOnWheels(std::vector<Solid>& out, double x0, double x1, double w, double z0, double z1, const Wheels& wh,
                  double well_width, double bottom, float refl) {
  const double top = std::min(wh.archTop(), z1);
  if (z1 > top) out.push_back(part(x0, x1, w, top, z1, bottom, refl));
  double x = x0;
  for (double a : wh.axles) {  // axles in increasing x
    const double lo = std::max(x0, a - wh.archHalf()), hi = std::min(x1, a + wh.archHalf());
    if (lo > x) out.push_back(part(x, lo, w, z0, top, bottom, refl));
    if (hi > lo && well_width > 0) out.push_back(part(lo, hi, well_width, z0, top, bottom, refl));
    x = std::max(x, hi);
  }
  if (x1 > x) out.push_back(part(x, x1, w, z0, top, bottom, refl));
}

// The tyres (black rubber returns little) of a body w wide.
void tyres(std::vector<Solid>& out, const Wheels& wh, double w, double bottom) {
  for (double a : wh.axles)
    for (double side : {-1.0, 1.0})
      out.push_back(Solid::wheel(Eigen::Vector3d(a, side * (0.5 * w - wh.inset - 0.5 * wh.width), bottom + wh.radius),
                                 wh.radius, wh.width, 0.0, 0.06f));
}

// The two outside mirrors at x along the object, `height` tall centred zc above the bottom, each
// reaching `reach` beyond the body's side (width w) and 2 cm into it. KITTI's boxes leave them
// out, so their points lie outside the labelled box (at most kPartsOutsideBoxM).
void mirrors(std::vector<Solid>& out, double x, double w, double zc, double height, double reach, double bottom,
             float refl) {
  for (double side : {-1.0, 1.0})
    out.push_back(Solid::box(Eigen::Vector3d(x, side * (0.5 * w + 0.5 * reach - 0.01), bottom + zc),
                             Eigen::Vector3d(0.1, reach + 0.02, height), 0.0, refl));
}

// A car's or van's body above its wheels: its top (a fraction of the height), the glass cabin on
// it from x0 to x1 (fractions of the length) and its width (a fraction of the body's), and the
// mirrors at the cabin's front: their centre above the body's top, height and reach.
struct Body {
  double top, cabin_x0, cabin_x1, cabin_width, mirror_above, mirror_height, mirror_reach;
};

std::vector<Solid> carLike(double l, double w, double h, const Wheels& wh, const Body& b, float refl) {
  const double bottom = -0.5 * h;
  std::vector<Solid> out;
  bodyOnWheels(out, -0.5 * l, 0.5 * l, w, 0.15, b.top * h, wh, w - 2 * (wh.width + 0.05), bottom, refl);
  tyres(out, wh, w, bottom);
  out.push_back(part(b.cabin_x0 * l, b.cabin_x1 * l, b.cabin_width * w, b.top * h, h, bottom, 0.5f * refl));  // glass
  mirrors(out, b.cabin_x1 * l - 0.1, w, b.top * h + b.mirror_above, b.mirror_height, b.mirror_reach, bottom, refl);
  return out;
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
  // A car: body to 58 % of the height, a shorter and narrower glass cabin on top; a van: a body
  // to 62 % and a cabin to its back.
  if (type == "Car")
    return carLike(l, w, h, {0.31, 0.2, 0.01, {-0.5 * l + 0.8, 0.5 * l - 0.85}}, {0.58, -0.36, 0.2, 0.9, 0.1, 0.12, 0.12},
                   refl);
  if (type == "Van")
    return carLike(l, w, h, {0.34, 0.22, 0.01, {-0.5 * l + 1.0, 0.5 * l - 0.9}}, {0.62, -0.5, 0.36, 0.97, 0.12, 0.2, 0.15},
                   refl);
  if (type == "Truck") {  // chassis, cab in front, cargo box behind; a tandem rear axle on long ones
    std::vector<Solid> out;
    Wheels wh{0.5, 0.3, 0.03, {-0.5 * l + 1.6, 0.5 * l - 1.2}};
    if (l >= 9.0) wh.axles.insert(wh.axles.begin() + 1, -0.5 * l + 2.9);
    out.push_back(part(-0.5 * l, 0.5 * l, 0.9 * w, 0.4, 1.0, bottom, 0.3f));
    // The cab's sides are cut over the front wheels; behind them the chassis is the well's wall.
    Wheels front = wh;
    front.axles = {wh.axles.back()};
    bodyOnWheels(out, 0.5 * l - 2.3, 0.5 * l, w, 0.4, 0.85 * h, front, 0.0, bottom, refl);
    out.push_back(part(-0.5 * l, 0.5 * l - 2.5, w, 1.0, h, bottom, 0.6f));  // the rear tyres are under it
    tyres(out, wh, w, bottom);
    mirrors(out, 0.5 * l - 0.25, w, 0.85 * h - 0.6, 0.4, 0.22, bottom, refl);
    return out;
  }
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
