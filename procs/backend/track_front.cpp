#include "backend/track_front.hpp"

#include <cmath>

#include "dlslot/types.hpp"

namespace dlslot::backend {

bool headingsAgree(double yaw_a, double yaw_b) { return std::abs(wrapAngle(yaw_a - yaw_b)) <= M_PI / 2; }

TrackFront withDetection(TrackFront front, double detection_yaw, double track_yaw) {
  if (headingsAgree(detection_yaw, track_yaw))
    ++front.agree;
  else
    ++front.disagree;
  return front;
}

TrackFront withMotion(TrackFront front, const Eigen::Vector2d& velocity, const Eigen::Vector2d& heading) {
  if (velocity.norm() > kSurelyForwardMps) front.motion_turned = velocity.dot(heading) < 0;
  return front;
}

bool turned(const TrackFront& front) {
  if (front.motion_turned) return *front.motion_turned;
  return front.disagree > front.agree;
}

}  // namespace dlslot::backend
