// Object velocities by finite differences of an object's positions in neighbouring scans, for
// the velocity RMSE of matched dynamic objects.
#pragma once

#include <vector>

#include "tracking_frames.hpp"

namespace dlslot::eval {

// World: positions are put in the world frame with each scan's pose (ground truth poses for the
// labels, the system's own poses for the tracks), differenced, and the velocity over ground is
// expressed in the scan's lidar axes. Sensor (no poses): positions are differenced directly in
// the lidar frames, giving the velocity relative to the moving sensor; both sides are then
// treated the same way, so they stay comparable.
enum class VelocityFrame { World, Sensor };
enum class Side { Truth, Tracks };

// Sets the velocity of every object of `side` that has the same id in the previous or next frame
// of `frames` (central difference when both exist). Objects that already have a velocity keep it
// unless `overwrite`. World needs the side's pose in every frame (throws std::invalid_argument).
void finiteDifferenceVelocities(std::vector<TrackingFrame>& frames, Side side, VelocityFrame velocity_frame,
                                bool overwrite);

// World: a label is dynamic when its mean speed over its whole life (first to last sighting in
// the world) is at least min_speed_mps. Sensor: every object moves relative to the sensor, so
// every label with a velocity counts.
void markDynamicLabels(std::vector<TrackingFrame>& frames, VelocityFrame velocity_frame, double min_speed_mps);

}  // namespace dlslot::eval
