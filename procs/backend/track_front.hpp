// Which end of a vehicle track is its front. A box and the box turned by pi are the same box, and
// detectors turn some boxes round; the window keeps every box of a track at the heading the track
// already has (SlidingWindow::alignedBox), so a track heads the way its first box did, right or
// wrong. Its published heading is turned by pi when the evidence says the front is the other end:
// - its motion, once it moves faster than a vehicle reverses in traffic: it heads where it goes;
//   what the motion said is kept while the vehicle is slower (stopped at a light, say);
// - until its motion has said, its detections: a detector's heading is right far more often than
//   not, so the majority of a track's detections points to its front, whatever its first box did.
#pragma once

#include <Eigen/Core>
#include <optional>

namespace dlslot::backend {

// Faster than a vehicle reverses in traffic (walking pace, < 2 m/s), with a margin for the
// velocity error of a young track (~1 m/s).
constexpr double kSurelyForwardMps = 3.0;

struct TrackFront {
  int agree = 0;                      // detections that pointed the way the track heads
  int disagree = 0;                   // detections turned by pi against it
  std::optional<bool> motion_turned;  // what its motion last said, once it was fast enough to say
};

// Whether two headings (yaw, rad, the same frame) point the same way: within 90 deg of each other.
// A box that does not is the other's turned round.
bool headingsAgree(double yaw_a, double yaw_b);

// The front after one more detection, of yaw detection_yaw, on a track heading track_yaw.
TrackFront withDetection(TrackFront front, double detection_yaw, double track_yaw);

// The front after a velocity estimate (world x-y, m/s) of a track heading along `heading` (world
// x-y): faster than kSurelyForwardMps, the motion decides.
TrackFront withMotion(TrackFront front, const Eigen::Vector2d& velocity, const Eigen::Vector2d& heading);

// Whether the track is published turned by pi: what its motion said, else the majority of its
// detections (a tie keeps the track's heading).
bool turned(const TrackFront& front);

}  // namespace dlslot::backend
