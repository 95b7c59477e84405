// A vehicle's speed along its heading from the ends of the side it shows (not in the paper).
//
// A car seen from the side (crossing traffic at an intersection, a car in the next lane) shows one
// flat face: the registration measures nothing along it (object_registration.hpp: degenerate, or
// partial with that direction removed), and the face's range (line_of_sight.hpp) moves only
// across it. The side's ends move with the car: its points' first and last along the heading are
// the car's back and front, for a side seen at all is seen whole unless something hides part of
// it. A lidar samples them at its azimuth step, so each end falls short by up to the step's width
// at the car's range, widened by the angle the side is seen at; the firing phase and the car's
// motion place the columns anew each scan. Where a box's centre moves with its 0.1-0.3 m noise,
// the ends' middle moves by that quantization (docs/object-motion.md, "A car's side and its ends").
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "backend/object_registration.hpp"
#include "backend/pair_speed.hpp"

namespace dlslot::backend {

// The extremes of the points' projections on the horizontal unit direction d (world).
struct SideEnds {
  double low = 0, high = 0;
  double length() const { return high - low; }
  double middle() const { return 0.5 * (low + high); }
};
// Nothing for fewer than two points.
std::optional<SideEnds> sideEnds(const ObjectPoints& points, const Eigen::Vector3d& d);

// The standard deviation (m) of one end: uniform over the columns' spacing along the side, the
// azimuth step at `range` over the sine of the angle between the side and the line of sight,
// and the floor (the sensor's own noise; a ring crossing the rounded end at another height).
double sideEndSigma(double range, double sin_angle, double azimuth_step_rad, double floor_m);

// One scan's ends along d with each end's standard deviation.
struct SideView {
  SideEnds ends;
  double end_sigma = 0;
};

// The pair's speed along d (both views along the same d): the middle's motion over dt. Nothing
// when either view's length is more than length_tolerance from the vehicle's (an end hidden
// behind something, a neighbour's points, an end-on view), or the two lengths differ by more than
// three standard deviations (an end hidden or uncovered between the scans: a car's length does
// not change).
//
// Its standard deviation: a middle's is s / sqrt(2) (two ends), a pair's sqrt((s0^2 + s1^2) / 2)
// / dt, but consecutive pairs share a scan and their errors are correlated by -1/2: the
// covariance of a run of pairs is the second-difference matrix, whose largest eigenvalue is twice
// its diagonal. Taken as independent (the chain's factors, the median of the last pairs), each
// pair is given sqrt(2) that, sqrt(s0^2 + s1^2) / dt, so that no combination of them (an
// alternation the chain would read as braking and accelerating) claims more than it holds.
std::optional<PairSpeed> sidePairSpeed(const SideView& previous, const SideView& current, const Eigen::Vector2d& d,
                                       double vehicle_length, double length_tolerance, double dt);

// One scan's side along d at `time` (s).
struct SideScan {
  double time = 0;
  SideView view;
};
// The line through the scans' middles, weighted least squares (a middle's variance s^2 / 2): its
// slope (m/s along d), the slope's standard deviation, and the scans' weighted mean time, where
// the slope holds best. Unlike a run of pairs, it takes each scan once: three scans 0.1 s apart
// give the speed to s / 0.2 s (s: one end's sigma), where the median of their two pairs claims
// sqrt(2) s / 0.1 s (sidePairSpeed), 2.8 times that.
// A scan counts when its length is within length_tolerance of the vehicle's and within three
// standard deviations of the median scan's (an end hidden or a stray point in that scan); then, of
// four scans or more, the one whose middle is furthest from the line through the others, beyond
// three standard deviations, is left out. Nothing with fewer than two scans.
struct SideLine {
  double speed = 0;
  double sigma = 0;
  double time = 0;
  int scans = 0;
};
std::optional<SideLine> sideLine(const std::vector<SideScan>& scans, double vehicle_length, double length_tolerance);

}  // namespace dlslot::backend
