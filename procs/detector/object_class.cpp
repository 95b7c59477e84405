#include "detector/object_class.hpp"

#include <algorithm>
#include <cmath>

namespace dlslot::detector {

namespace {

// How far (in tan of elevation) below the top beam a cluster's highest point may be and still
// count as cut off by it (the HDL-64E's top beams are 0.0058 apart).
constexpr double kTopMargin = 0.006;
// A low cluster (under the car window's height) is a vehicle's back or front only when it is a face:
// thinner than this bird's-eye and across the line of sight (its axis more than 65 deg from the ray).
constexpr double kFaceMaxDepth_m = 0.8;
const double kFaceMaxCos = std::cos(65.0 * M_PI / 180.0);
// A truck's back is a plane: at least this share of its points on the rectangle's edges.
constexpr double kTruckBackEdgeFraction = 0.8;
// Within this range a van (2-2.5 m) reaches above the HDL-64E's top beam (1.73 m + 0.035 x range).
constexpr double kBesideRange_m = 10.0;

Eigen::Vector2d axisOf(double yaw) { return {std::cos(yaw), std::sin(yaw)}; }

double logit(double p) {
  p = std::clamp(p, 0.01, 0.995);
  return std::log(p / (1 - p));
}

// Confidence from the evidence: enough points for the class, an L-shape with points on its edges
// (vehicles), and how much of the box was seen rather than completed from the prior.
double confidence(int points, double points_ref, double edge_fraction, double seen_share) {
  const double support = 1.0 - std::exp(-points / points_ref);
  return 0.5 + 0.5 * support * edge_fraction * (0.6 + 0.4 * std::clamp(seen_share, 0.0, 1.0));
}

Box makeBox(const Rectangle& r, const ClusterShape& s, const std::string& type, double score) {
  Box b;
  const double h = s.max_z - s.ground_z;
  b.center = Eigen::Vector3d(r.center.x(), r.center.y(), s.ground_z + 0.5 * h);
  b.size = Eigen::Vector3d(r.length, r.width, h);
  b.yaw = r.yaw;
  b.type = type;
  b.score = score;
  b.id = -1;
  return b;
}

}  // namespace

Rectangle completeVehicle(const Rectangle& seen, double prior_length_m, double prior_width_m, double side_min_m) {
  Rectangle r = seen;
  double seen_l = seen.length, seen_w = seen.width, yaw = seen.yaw;
  const Eigen::Vector2d radial = seen.center.norm() > 1e-6 ? Eigen::Vector2d(seen.center.normalized()) : Eigen::Vector2d(1, 0);
  // A face no wider than a car's back, across the line of sight: the back or the front (with the
  // roof seen behind it, it may be a metre or more deep).
  if (seen_l < side_min_m && seen_l <= prior_width_m + 0.4 && std::abs(axisOf(yaw).dot(radial)) < 0.7) {
    std::swap(seen_l, seen_w);
    yaw += M_PI / 2;
  }
  const double l = std::max(seen_l, prior_length_m), w = std::max(seen_w, prior_width_m);
  const Eigen::Vector2d u = axisOf(yaw), v(-u.y(), u.x());
  // Grow away from the sensor along each axis: the seen faces are the near ones.
  const double su = u.dot(seen.center) >= 0 ? 1.0 : -1.0, sv = v.dot(seen.center) >= 0 ? 1.0 : -1.0;
  r.center = seen.center + su * 0.5 * (l - seen_l) * u + sv * 0.5 * (w - seen_w) * v;
  r.length = l;
  r.width = w;
  yaw = wrapAngle(yaw);
  if (yaw > M_PI / 2) yaw -= M_PI;
  if (yaw <= -M_PI / 2) yaw += M_PI;
  r.yaw = yaw;
  return r;
}

namespace {

// A person's or a cyclist's box grown to at least the prior footprint about its seen centre. (Moving
// the centre away from the sensor by half the gained depth, as for vehicles, put the centres 3 cm
// farther from the labels' on intersection seed 1: people are seen nearly whole in depth.)
Rectangle completeSmall(const Rectangle& seen, double prior_length_m, double prior_width_m) {
  Rectangle r = seen;
  r.length = std::max(seen.length, prior_length_m);
  r.width = std::max(seen.width, prior_width_m);
  return r;
}

std::optional<Box> truckBack(const ClusterShape& s, bool cut_at_top, const ClassConfig& cfg) {
  const Rectangle& seen = s.seen;
  const double h = s.max_z - s.ground_z;
  if (seen.center.norm() < 1e-6 || s.profile_step > cfg.max_vehicle_profile_step_m) return std::nullopt;
  // Tall (a truck's window's height, less what the top beam may have cut off) and a clean plane: its
  // points on the rectangle's edges (roadside trees and bushes as wide and tall have few there).
  const double min_h = cut_at_top ? cfg.van.max_height_m - 0.5 : cfg.truck.min_height_m;
  if (h < min_h || h > cfg.truck.max_height_m || seen.edge_fraction < kTruckBackEdgeFraction) return std::nullopt;
  const Eigen::Vector2d radial = seen.center.normalized();
  // The rectangle's side across the line of sight is the back; the other runs away from the sensor.
  const bool length_across = std::abs(axisOf(seen.yaw).dot(radial)) < std::abs(axisOf(seen.yaw + M_PI / 2).dot(radial));
  const double face = length_across ? seen.length : seen.width, depth = length_across ? seen.width : seen.length;
  if (face < cfg.truck_min_face_m || face > cfg.truck.max_width_m || depth >= cfg.truck.min_length_m) return std::nullopt;
  Rectangle r = seen;
  r.length = depth;
  r.width = face;
  r.yaw = length_across ? seen.yaw + M_PI / 2 : seen.yaw;
  const Rectangle full = completeVehicle(r, cfg.truck_prior_length_m, face, 0.0);
  return makeBox(full, s, "Truck", logit(confidence(s.num_points, 60, seen.edge_fraction, depth / full.length)));
}

// A truck's or a bus's side right beside the ego (intersection seed 8: a 10 m truck in the next lane
// for 53 of 60 frames): cut by the top beam, thin, as long as a truck. Nothing else completes a
// stretch that long; its back and front stay hidden. Grown away from the sensor to a truck's width
// and height (the top beam saw only its lower 2 m).
std::optional<Box> truckSide(ClusterShape s, bool cut_beside, const ClassConfig& cfg) {
  const Rectangle& seen = s.seen;
  if (!cut_beside || seen.width >= kFaceMaxDepth_m || seen.edge_fraction < kTruckBackEdgeFraction) return std::nullopt;
  if (seen.length < cfg.truck.min_length_m || seen.length > cfg.truck.max_length_m) return std::nullopt;
  const double width = 0.5 * (cfg.truck.min_width_m + cfg.truck.max_width_m);
  const Rectangle full = completeVehicle(seen, seen.length, width, 0.0);
  s.max_z = std::max(s.max_z, s.ground_z + cfg.truck.min_height_m);
  return makeBox(full, s, "Truck", logit(confidence(s.num_points, 60, seen.edge_fraction, 0.5)));
}

}  // namespace

std::optional<Box> classifyCluster(const ClusterShape& s_in, const ClassConfig& cfg) {
  ClusterShape s = s_in;
  const double bottom = s.min_z - s.ground_z;
  const Rectangle& seen = s.seen;
  if (bottom > cfg.max_bottom_m) return std::nullopt;  // hangs above the ground: canopy, sign, overhang
  const bool cut_at_top = s.max_tan >= cfg.top_tan - kTopMargin;
  // Cut off by the top beam (beside the ego, up a slope), the seen height is only a lower bound: the
  // windows' minimum heights do not apply, and the box is at least a car's height.
  if (cut_at_top) s.max_z = std::max(s.max_z, s.ground_z + cfg.car.min_height_m);
  const double h = s.max_z - s.ground_z;
  // Poles and trunks: thin, and taller than a person or reaching the top beam.
  if (seen.length <= cfg.pole_max_width_m && (cut_at_top || h > cfg.pedestrian.max_height_m)) return std::nullopt;
  const double seen_area = seen.length * seen.width;

  // A vehicle's side is not level (bonnet, roof, boot; a truck's cab below its box): a thin, level
  // stretch as long as a side is a wall or a barrier, unless the top beam cut it off right beside
  // the ego (a van there shows a level band). (A wide L-shape is a corner, level or not: a partly
  // seen car shows only its roof's rear part.)
  const bool cut_beside = cut_at_top && seen.center.norm() < kBesideRange_m;
  // A truck's or a bus's back from behind (highway seeds 1-5: 67 of the vehicle misses, a truck
  // 28-38 m ahead): a face wider than any car or van, across the line of sight, tall or cut by the
  // top beam, seen less deep than a truck is long. Completed away from the sensor to the truck prior.
  if (std::optional<Box> back = truckBack(s, cut_at_top, cfg)) return back;
  if (std::optional<Box> side = truckSide(s, cut_beside, cfg)) return side;
  const bool level_side = seen.length >= cfg.car_side_min_m && seen.width < cfg.level_max_width_m && !cut_beside &&
                          s.profile_step < cfg.min_profile_step_m;
  if (level_side) return std::nullopt;
  // Tops that differ by more than a van's bonnet and roof: a tree or a bush, not a vehicle.
  const bool ragged_top = s.profile_step > cfg.max_vehicle_profile_step_m;

  // Vehicles seen whole (a van or a truck is its own prior).
  if (!ragged_top && cfg.truck.contains(seen.length, seen.width, h, cut_at_top))
    return makeBox(seen, s, "Truck", logit(confidence(s.num_points, 60, seen.edge_fraction, 1.0)));
  if (!ragged_top && cfg.van.contains(seen.length, seen.width, h, cut_at_top))
    return makeBox(seen, s, "Van", logit(confidence(s.num_points, 50, seen.edge_fraction, 1.0)));

  // People: small footprint, person height, not cut off by the top beam (so not a pole or a wall).
  const bool person_height = !cut_at_top;
  if (person_height && cfg.pedestrian.contains(seen.length, seen.width, h))
    return makeBox(completeSmall(seen, cfg.pedestrian_prior_length_m, cfg.pedestrian_prior_width_m), s, "Pedestrian",
                   logit(confidence(s.num_points, 20, 1.0, 1.0)));
  // A cyclist seen from the side: a bicycle's length, a person's height, narrow.
  if (person_height && cfg.cyclist.contains(seen.length, seen.width, h) && h >= cfg.car.max_height_m - 0.3 &&
      seen.length < cfg.car_side_min_m && s.profile_step >= cfg.cyclist_min_profile_step_m)
    return makeBox(completeSmall(seen, cfg.cyclist_prior_length_m, cfg.cyclist_prior_width_m), s, "Cyclist",
                   logit(confidence(s.num_points, 25, 1.0, 1.0)));

  // Cars, also when partly seen: completed to the prior, then checked against the car window.
  const double vehicle_min_height =
      cfg.car.min_height_m - cfg.vehicle_min_height_drop_per_m * seen.center.norm();
  // Below the car window's own lower end only a back or a front is taken (a thin face across the
  // line of sight): far guard rails and kerbside bushes are as low but run along the rays or are blobs.
  const Eigen::Vector2d radial = seen.center.norm() > 1e-6 ? Eigen::Vector2d(seen.center.normalized()) : Eigen::Vector2d(1, 0);
  const bool low_face = seen.width < kFaceMaxDepth_m && std::abs(axisOf(seen.yaw).dot(radial)) < kFaceMaxCos;
  const bool vehicle_height = h <= cfg.van.max_height_m &&
                              (h >= cfg.car.min_height_m || cut_at_top || (h >= vehicle_min_height && low_face));
  if (vehicle_height && !ragged_top && seen.length >= cfg.min_vehicle_face_m && seen.length <= cfg.van.max_length_m && seen.width <= cfg.van.max_width_m) {
    // Neither a side nor a back seen but a blob of both: a corner (an L) only when the points lie on
    // its edges; foliage fills it.
    const bool blob = seen.length < cfg.car_side_min_m && seen.width > 0.8;
    if (blob && seen.edge_fraction < cfg.min_corner_edge_fraction)
      return makeBox(seen, s, kUnknownType, logit(0.2));
    // A wide cluster as long as a side still needs some of its points on the edges (foliage has
    // almost none there).
    if (seen.width > 0.8 && seen.edge_fraction < cfg.min_side_edge_fraction) return std::nullopt;
    const Rectangle full = completeVehicle(seen, cfg.car_prior_length_m, cfg.car_prior_width_m, cfg.car_side_min_m);
    const double share = seen_area / std::max(1e-6, full.length * full.width) +
                         0.5 * std::max(seen.length, seen.width) / full.length;
    const double score = logit(confidence(s.num_points, 40, std::max(0.3, seen.edge_fraction), share));
    // vehicle_height has checked the lower end (dropping with range), so the window's is not used.
    if (cfg.car.contains(full.length, full.width, h, /*height_is_lower_bound=*/true)) return makeBox(full, s, "Car", score);
    if (cfg.van.contains(full.length, full.width, h, cut_at_top)) return makeBox(full, s, "Van", score);
  }

  // Object-sized but no class: removed for the odometry, never tracked.
  if (seen.length <= cfg.unknown_max_length_m && h >= cfg.unknown_min_height_m && h <= cfg.unknown_max_height_m &&
      seen.length > cfg.pole_max_width_m)
    return makeBox(seen, s, kUnknownType, logit(0.2));
  return std::nullopt;
}

}  // namespace dlslot::detector
