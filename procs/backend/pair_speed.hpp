// A vehicle's speed along one horizontal direction from one scan pair of its points (not in the
// paper). Two parts of a far vehicle's points move with it where the registration cannot follow
// (object_registration.hpp: too few points, degenerate): the face it shows the sensor, along the
// line of sight (line_of_sight.hpp), and the ends of the side it shows, along its heading
// (side_ends.hpp). Each gives one speed per scan pair along one direction, nothing across it; the
// chain takes each pair as a factor (sight_speed_factor.hpp), a young track the median of its last
// few pairs of the face (below) or the line through its side's scans (sideLine).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "backend/registered_velocity.hpp"

namespace dlslot::backend {

// One scan pair's speed (m/s) along the horizontal unit u (world): the measured part's position
// along u in the current scan minus the previous one, over the time between them.
struct PairSpeed {
  Eigen::Vector2d u = Eigen::Vector2d::UnitX();
  double speed = 0;
  double sigma = 0;  // its standard deviation (m/s)
  // The sensor's displacement along u between the two scans (m) in the ego poses the pair was
  // measured with: speed x dt minus it is the motion against the sensor (sight_speed_factor.hpp).
  double sensor_displacement = 0;
  int points = 0;  // the fewer of the two scans' points
  // Whether both scans lie on the line the face follows over its last scans (faceSamplesOnLine);
  // nothing where too few scans tell.
  std::optional<bool> on_line;
};

// Whether a pair counts by itself: where the face's scans judged it, their verdict; else when it
// holds trusted_points points in both scans.
bool countsAlone(const PairSpeed& p, int trusted_points);

// The median of the counted pairs' speeds as a velocity measured along the newest counted pair's u
// alone, with the median of their standard deviations there and no information across it. A pair
// judged off its face's line never counts; one that is not judged and holds fewer than
// trusted_points points counts only when another pair not judged off its line agrees with it,
// within two standard deviations of their difference: below 20 points 38 % of the line-of-sight
// pairs are over 1 m/s off, and two such pairs rarely agree (the median of two pairs is their mean,
// so one stray pair took a car's first velocity 6 m/s off). Nothing without pairs that count.
std::optional<VelocityEvidence> medianPairVelocity(const std::vector<PairSpeed>& pairs, int trusted_points = 0);

}  // namespace dlslot::backend
