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
// of `frames` (central difference when both exist). With half_span_s > 0 the central difference is
// taken over the widest symmetric span of at most +-half_span_s whose two ends saw the object
// (falling back to the neighbours): a human labeller's boxes jitter by 0.1-0.15 m, which
// differences of neighbouring frames (0.2 s apart) turn into 0.5-0.7 m/s of false motion, while
// over +-0.5 s it is ~0.15 m/s. Objects that already have a velocity keep it unless `overwrite`.
// World needs the side's pose in every frame (throws std::invalid_argument).
void finiteDifferenceVelocities(std::vector<TrackingFrame>& frames, Side side, VelocityFrame velocity_frame,
                                bool overwrite, double half_span_s = 0.0);

// The half span for the labels' differences: a human labeller's boxes (KITTI's) jitter, the
// simulator's are exact, and neighbouring frames are the best truth for exact labels (0), +-0.5 s
// for a human's. Told apart by the labels themselves, as the map evaluation does: KITTI labels
// only what camera 2 sees, ahead of the sensor; a label behind it (x < 0) exists only where the
// labelling is all around, the simulator's.
double labelVelocityHalfSpan(const std::vector<TrackingFrame>& frames);

// World: a label is dynamic when its mean speed over its whole life (first to last sighting in
// the world) is at least min_speed_mps. Sensor: every object moves relative to the sensor, so
// every label with a velocity counts.
void markDynamicLabels(std::vector<TrackingFrame>& frames, VelocityFrame velocity_frame, double min_speed_mps);

}  // namespace dlslot::eval
