// A far vehicle's speed along the line of sight from the face it shows (not in the paper).
//
// Beyond ~50 m a car is 10-100 points on 2-5 scan rings: too few planes for the registration
// (object_registration.hpp: too few points, degenerate, poor fit), so a young far track's velocity
// is the line through its few boxes, 1.2-1.9 m/s off beyond 70 m on the simulated drives. But the
// points it has lie on the one face the sensor sees (an oncoming car's front, a leading car's back),
// and a lidar measures range to 2 cm: from one scan to the next that face moves by the car's
// motion along the line of sight. Measured on the simulated highway and highway-jam (pairs with no
// registration, against the true velocity), pairs with 20+ points in both scans: 0.24-0.39 m/s
// RMS among those within 1 m/s, but 13-31 % beyond it (a ring crossing from bumper to bonnet, a
// neighbour's points in the box); below 20 points, half of them beyond it. Hence the median over
// the last few pairs (medianPairVelocity), and a test against the boxes' line before it is used
// (fuseVelocities). Better still, a pair is judged by the face's other scans: a face whose range
// jumps to another part of the car leaves the line the face follows over its last scans
// (faceSamplesOnLine).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "backend/object_registration.hpp"
#include "backend/pair_speed.hpp"
#include "dlslot/types.hpp"

namespace dlslot::backend {

// Where the face an object shows lies along the horizontal unit direction u (world): the median
// projection of its points within face_depth (m) of their 10th percentile. The percentile, not the
// nearest point, so a stray point in front does not move it; the band, so the face's points and
// not the rest of the body set the median. Nothing for an empty cloud.
std::optional<double> nearFaceRange(const ObjectPoints& points, const Eigen::Vector3d& u, double face_depth = 0.3);

// True when the box (lidar frame) shows the sensor its front or back: its heading within
// max_angle_deg of the line of sight to its centre. A face turned by a from head-on spreads its
// points over its width x sin(a) in depth, and the statistic above then depends on where the rings
// fall: on the simulated drives pairs within 10 deg were 0.18-0.23 m/s off in the median, those
// turned 20-45 deg 1.3-2.0 m/s (crossing and turning traffic at an intersection). At 10 deg a
// car's 1.8 m wide face spans the 0.3 m face depth.
bool facesTheSensor(const Box& box, double max_angle_deg);

// Which of the samples (t_i, y_i) lie within tolerance of the robust line through them: Siegel's
// repeated-median line (each sample's median slope to the others, their median, then the median
// intercept), which fewer than half of the samples cannot move. None when half or more lie off it:
// the line is then the outliers' as much as the face's (a far truck's back whose range zigzags
// from ring to ring by 0.3-0.5 m). Empty for fewer than 4 samples: with three, one jump in the
// newest is not told from a change of speed. (The Theil-Sen line, the median of all pairwise
// slopes, breaks down at 29 %: a young van's first of four scans 0.7 m off tilted it so that the
// other three were judged off too.)
std::vector<bool> faceSamplesOnLine(const std::vector<double>& t, const std::vector<double>& y, double tolerance);

// The horizontal unit direction from the sensor to the points' centroid (world); nothing when they
// are (nearly) above it.
std::optional<Eigen::Vector3d> lineOfSight(const ObjectPoints& points, const Eigen::Vector3d& sensor);

}  // namespace dlslot::backend
