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
// Where something nearer hides one end, the other still moves with the car ("A side cut short").
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "backend/object_registration.hpp"
#include "backend/pair_speed.hpp"
#include "dlslot/types.hpp"

namespace dlslot::backend {

// The extremes of the points' projections on the horizontal unit direction d (world).
struct SideEnds {
  double low = 0, high = 0;
  double length() const { return high - low; }
  double middle() const { return 0.5 * (low + high); }
};
// Nothing for fewer than two points.
std::optional<SideEnds> sideEnds(const ObjectPoints& points, const Eigen::Vector3d& d);

// The sine of the angle between a box's heading and the line of sight to its centre (0 end-on).
double sideSine(const Box& box);
// The spacing (m) of the lidar's columns along a side seen at that angle: the azimuth step at
// `range` over the sine.
double columnSpacing(double range, double sin_angle, double azimuth_step_rad);
// The standard deviation (m) of one end: uniform over the columns' spacing along the side, and
// the floor (the sensor's own noise; a ring crossing the rounded end at another height).
double sideEndSigma(double range, double sin_angle, double azimuth_step_rad, double floor_m);

// Which of a scan's two ends along its box's heading the sensor saw whole. A car that something
// nearer hides in part (a car passing in front of it, a post, the corner it comes round) shows a
// side cut short at one end; its other end still moves with it.
struct EndsSeen {
  bool low = true, high = true;
  bool both() const { return low && high; }
  // The same ends named along the opposite direction when `flip`.
  EndsSeen flipped(bool flip) const { return flip ? EndsSeen{high, low} : *this; }
};

// A scan's points by azimuth, in bins one azimuth step wide, for endsSeen. With `objects`, only
// the points that could hide one of them: nearer than the farthest of their points and within
// their elevations (an atan2 for each: object_registration_bench, EndsSeen).
class AzimuthIndex {
 public:
  AzimuthIndex(const PointCloud& scan, double step_rad, const std::vector<const ObjectPoints*>& objects = {});
  const PointCloud& scan() const { return *scan_; }
  double step() const { return step_; }
  // The indices of the points whose azimuth bins overlap [from, to] (rad, to - from < 2 pi).
  std::vector<int> near(double from, double to) const;

 private:
  const PointCloud* scan_;
  double step_;
  std::vector<int> order_;  // point indices sorted by bin
  std::vector<int> start_;  // bin b holds order_[start_[b], start_[b + 1])
};

// The ends of an object's points (lidar frame) along its crop volume's heading (the box it was cut
// out of the scan with, dlslot/box_filter.hpp), each seen unless
// - the lidar's columns beside it (the azimuths of the points within one column's spacing of it,
//   two steps either way) hit something nearer than it, outside the crop and within the
//   elevations of the object's points (the rings that hit it): the side may go on behind that;
// - it lies within one column's spacing of the crop's end, which may have cut it.
// The spacing is the azimuth step at the box's range over the sine of the side's angle to the
// line of sight (sideEndSigma).
EndsSeen endsSeen(const AzimuthIndex& index, const ObjectPoints& points, const Box& crop);

// Which of a scan's ends count, given its ends along d, those endsSeen saw (named along d) and
// its point count, for a vehicle of vehicle_length whose box's centre lies at box_middle along d,
// box_sigma off:
// - a side as long as the vehicle (no more than length_tolerance shorter) counts both: its ends
//   are where they are whatever the test says, which also hides an end one ring sees past an
//   occluder on another (refusing those scans cost the intersection 2-10 %);
// - a shorter side the test saw whole contradicts it: neither;
// - the one end it saw counts from min_points points (with fewer, where the rings happen to fall)
//   and where the box puts it, within three box sigmas: an end that returned no points (glass; far
//   away, a ring that missed the body) is short of the car with nothing in front of it.
EndsSeen endsThatCount(const SideEnds& ends, EndsSeen seen, int points, double vehicle_length, double length_tolerance,
                       double box_middle, double box_sigma, int min_points);

// One scan's ends along d with each end's standard deviation, and which of them count.
struct SideView {
  SideEnds ends;
  double end_sigma = 0;
  EndsSeen seen{};
};

// The pair's speed along d (both views along the same d): the middle's motion over dt. Nothing
// when either view's length is more than length_tolerance from the vehicle's (an end hidden
// behind something, a neighbour's points, an end-on view), or the two lengths differ by more than
// three standard deviations (an end hidden or uncovered between the scans: a car's length does
// not change). Where a view counts one end only (endsThatCount), the motion of an end both count:
// one end's variance is twice a middle's.
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
// A scan that counts both ends counts when its length is within length_tolerance of the vehicle's
// and within three standard deviations of the median such scan's (an end hidden or a stray point
// in that scan); one that counts one end, by that end alone, and only among four scans or more:
// it has no length to be checked by, so the test below is its only check. Each end's offset from
// the middle is its own unknown beside the line's, and, of four scans or more, the one furthest
// from the line through the others, beyond three standard deviations, is left out. Nothing
// without two scans at distinct times on a common end.
struct SideLine {
  double speed = 0;
  double sigma = 0;
  double time = 0;
  int scans = 0;
};
std::optional<SideLine> sideLine(const std::vector<SideScan>& scans, double vehicle_length, double length_tolerance);

}  // namespace dlslot::backend
