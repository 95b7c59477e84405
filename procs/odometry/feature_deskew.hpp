// A scan's features put back on their rays (correctElevation) and moved to its reference instant
// (deskewFeatures) before registration. A spinning lidar fires
// its columns over one sweep while the vehicle moves (1 m of a 0.1 s sweep at 10 m/s), so a raw
// scan is sheared; the features of each scan are de-skewed with the vehicle's motion of the
// previous frame, as KISS-ICP does with its constant-velocity model.
#pragma once

#include "dlslot/deskew.hpp"
#include "feature_extraction.hpp"

namespace dlslot::odometry {

// The sweep's motion predicted from `per_frame` (T_prev_cur, one scan = one revolution of
// `period_s`): the vehicle's motion in the plane of its road, velocity (x, y) and yaw rate, what
// it keeps from one scan to the next. Not its vertical velocity, roll and pitch rates: those are
// the body riding on its suspension at 1-2.5 Hz, turned round a frame later, and the odometry's
// per-frame height and pitch errors (2 cm, 0.2 deg); with them the de-skew added a distortion
// (simulated highway seed 1: per-frame rotation error 0.085 -> 0.102 deg, planar 0.086; urban-loop
// seed 9 with the pitch rate: 0.24 -> 0.60 deg; docs/ego.md).
BodyTwist vehicleTwist(const Pose& per_frame, double period_s);

// Every point of the four feature clouds into the lidar frame of the scan's reference instant.
void deskewFeatures(ScanFeatures& features, const SweepTiming& sweep, const BodyTwist& twist);

// Every point of the four feature clouds put back on its ray: its elevation raised by
// `angle_rad`, the lidar's vertical-angle error (dlslot/vertical_angle.hpp); 0 leaves them.
void correctElevation(ScanFeatures& features, double angle_rad);

}  // namespace dlslot::odometry
