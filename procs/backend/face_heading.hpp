// A vehicle's heading from the faces its points show (not in the paper).
//
// A moving vehicle's velocity points along its heading (vehicle_motion_factor.hpp), so a heading
// error turns the velocity sideways by speed x error: on the simulated highway the mature tracks'
// sideways velocity error was their heading error times their speed (correlation 0.99, 0.17 m/s
// at 25 m/s, i.e. 0.4 deg), 60 % of it faster than a second. The boxes give the heading to 0.04
// rad each and the chain's positions over the 1 s window to ~0.4 deg. The points of the sides the
// sensor sees give it far better: a lidar measures range to 2 cm, and a car's side is 4 m long and
// its back 1.8 m wide.
//
// The fit: the visible faces (the one or two sides of the box turned towards the sensor) as two
// perpendicular lines, heading and offsets by Gauss-Newton on the points' distances to them, with
// Cauchy weights (mirrors, wheels, a neighbour's points, rounded corners). Its information is the
// Gauss-Newton Hessian over the residuals' own variance, floored by the sensor's noise and shrunk
// for the correlation of neighbouring points, as the registration's is (object_registration.hpp).
#pragma once

#include <Eigen/Core>
#include <optional>

#include "backend/object_registration.hpp"
#include "dlslot/types.hpp"

namespace dlslot::backend {

struct FaceHeadingOptions {
  double margin = 0.4;            // m: points this far outside the box still count (its noise)
  // The band of the height (fractions from the bottom) whose points are used: a vehicle's body
  // between its wheels and its windows, its widest and most upright part.
  double low_cut = 0.3;
  double high_cut = 0.55;
  int min_points = 20;            // fewer on the faces: no measurement
  double min_face_span = 0.8;     // m: a face whose points span less is not used
  double cauchy_scale = 0.05;     // m
  double point_sigma = 0.02;      // m: floor of the residuals' standard deviation
  double information_scale = 0.1; // neighbouring points are correlated
  double accuracy_rad = 0.0035;   // added in quadrature: the shape's own error (rounded corners)
  double max_sigma_rad = 0.02;    // a worse fit is no measurement
  double max_turn_rad = 0.26;     // a fit this far from the box's heading (15 deg) went wrong
  int iterations = 6;
};

struct FaceHeading {
  double yaw = 0;    // world, the box's axis within pi/2 of the box's yaw
  double sigma = 0;  // rad
  int points = 0;    // on the faces used
  int faces = 0;     // 1 or 2
};

// The heading of `box` (world frame) from its object's points (world) seen from `sensor` (world).
// Nothing when the points do not measure it (too few, a face too short, a poor fit).
std::optional<FaceHeading> faceHeading(const ObjectPoints& points, const Box& box, const Eigen::Vector3d& sensor,
                                       const FaceHeadingOptions& options = {});

}  // namespace dlslot::backend
