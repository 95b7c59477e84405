// The ego pose X_t that puts the detections of scan t in the world frame (eq. 1): the
// backend's optimized pose when it has one for t, else the last optimized pose chained with the
// odometry's relative motions since, X_t = X_f * T_f^{f+1} * ... * T_{t-1}^t (across a scan the
// odometry never saw, with its own poses: X_t = X_f * inv(O_f) * O_t).
#pragma once

#include <map>
#include <string>

#include "dlslot/types.hpp"

namespace dlslot::tracker {

enum class PoseSource {
  Slot,       // the backend's optimized pose of this very scan
  Odometry,   // the last optimized pose (or the odometry's own pose) chained with odometry
  Predicted,  // odometry of some scan missing: its motion repeated (constant velocity)
};
const char* poseSourceName(PoseSource s);  // "slot" | "odometry" | "predicted"

struct EgoPose {
  Pose X = Pose::Identity();  // T_world_lidar
  PoseSource source = PoseSource::Predicted;
};

class EgoPoseChain {
 public:
  // SLOT_STATE: optimized T_world_lidar of `frame`.
  void addOptimized(int frame, const Pose& X);
  // ODOMETRY: the odometry's T_world_lidar and its relative motion T_prev_cur for `frame`.
  void addOdometry(int frame, const Pose& pose, const Pose& delta);
  EgoPose poseAt(int frame) const;
  // Forgets what scans before `frame` no longer need (keeps the latest optimized pose before it).
  void forgetBefore(int frame);

 private:
  std::map<int, Pose> optimized_;
  std::map<int, Pose> odometry_pose_, odometry_delta_;
};

}  // namespace dlslot::tracker
