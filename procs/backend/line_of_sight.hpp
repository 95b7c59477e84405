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
// the last few pairs, and a test against the boxes' line before it is used (fuseVelocities).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "backend/object_registration.hpp"
#include "backend/registered_velocity.hpp"
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

// The horizontal unit direction from the sensor to the points' centroid (world); nothing when they
// are (nearly) above it.
std::optional<Eigen::Vector3d> lineOfSight(const ObjectPoints& points, const Eigen::Vector3d& sensor);

// One scan pair's speed (m/s) along u: the face's range in the current scan along the previous
// scan's line of sight, minus the previous one, over the time between them.
struct SightSpeed {
  Eigen::Vector2d u = Eigen::Vector2d::UnitX();
  double speed = 0;
  // The sensor's displacement along u between the two scans (m) in the ego poses the pair was
  // measured with: speed x dt minus it is the face's motion against the sensor (sight_speed_factor.hpp).
  double sensor_displacement = 0;
  int points = 0;  // the fewer of the two scans' points
};

// The median of the counted pairs' speeds as a velocity measured along the newest counted pair's u
// alone, with standard deviation sigma_mps there and no information across it. A pair of fewer
// than trusted_points points counts only when another pair agrees with it, within two standard
// deviations of the difference of two good pairs (2 sqrt(2) sigma_mps): below 20 points 38 % of
// the pairs are over 1 m/s off, and two such pairs rarely agree (the median of two pairs is their
// mean, so one stray pair took a car's first velocity 6 m/s off). Nothing without pairs that count.
std::optional<VelocityEvidence> lineOfSightVelocity(const std::vector<SightSpeed>& pairs, double sigma_mps,
                                                    int trusted_points = 0);

}  // namespace dlslot::backend
