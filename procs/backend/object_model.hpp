// One object's accumulated points: its points of the last few consecutive scans merged in the
// world frame of the newest scan, each older scan's points carried along by the registrations
// that measured the object's motion since (M of eq. 10's pose change, in the world). A car seen
// from behind shows its rear in one scan and a little of a side in the next as it turns or
// drifts across the view; the model holds both, so the next scan registers against more sides
// than the previous scan alone gives (fewer too-few-points, degenerate and partial outcomes),
// and its extent says how large the car is where it has been seen (refinedBox).
//
// Bounded: points older than model_frames scans are dropped; past max_model_points the rest are
// thinned to one point per half voxel (the registration's target spacing), the newest kept in
// each cell, and cut to max_model_points, newest first.
#pragma once

#include <optional>
#include <vector>

#include "backend/object_registration.hpp"
#include "backend/se3.hpp"

namespace dlslot::backend {

class ObjectModel {
 public:
  // Adds one scan's points (world frame, `frame`). `motion`: the object's measured motion since
  // the model's latest scan (world frame, o_frame = M o_previous), which carries the older points
  // along; none (no registration, or a gap): the model restarts from this scan.
  void update(const ObjectPoints& scan, int frame, const std::optional<Pose>& motion, double range,
              const RegistrationOptions& options);

  const ObjectPoints& points() const { return points_; }
  int frame() const { return frame_; }
  // How many scans the points come from.
  int scans() const;

 private:
  ObjectPoints points_;
  std::vector<int> frames_;  // each point's scan
  int frame_ = -1;
};

// A box (T_world_box and size l, w, h) made to cover an object's accumulated points (world
// frame), seen from `sensor` (world frame), in the ground plane, axis by axis (the box's length
// and width directions):
// - seen end to end (the points span at least the box's size): the size is the points' extent,
//   the centre its middle;
// - one end faces the sensor and the points stop short of the other (a car seen from behind: its
//   rear, not its length): the box keeps its size and its near end goes where the points begin,
//   the faces a lidar sees being the object's surface to a few centimetres where a detector's box
//   is off by decimetres;
// - otherwise (the sensor beside that span) the box keeps its size and moves the least that makes
//   it hold the points.
// The extremes' `trim` fraction at each end is left out (a stray point of the ground or a
// neighbour in the grown box). Height and yaw stay the box's. Fewer than `min_points` points: the
// box as it is.
struct RefinedBox {
  Pose pose = Pose::Identity();
  Eigen::Vector3d size = Eigen::Vector3d::Zero();
};
RefinedBox refinedBox(const Pose& box, const Eigen::Vector3d& size, const ObjectPoints& points,
                      const Eigen::Vector3d& sensor, int min_points, double trim = 0.005);

}  // namespace dlslot::backend
