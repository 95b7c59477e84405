// Where the objects to take out of the map were, frame by frame: the backend's tracks (world
// frame), kept for a few seconds so that a keyframe's points are removed with what was learned
// after it (a track confirmed or found to move later), and followed through the frames where the
// detector missed them (interpolated between two sightings, or carried at the track's velocity).
#pragma once

#include <map>
#include <string>
#include <vector>

#include "dlslot/types.hpp"

namespace dlslot::mapper {

// One track of a SLOT_STATE, world frame.
struct TrackSnapshot {
  int id = -1;
  Box box;                                      // T_world_object centre, size, yaw
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  // m/s, world frame
  bool dynamic = false;
  bool observed = true;                         // seen in this frame (not coasting)
};

class TrackBoxes {
 public:
  // margin: growth of every box on each side; follow_frames: the longest gap bridged;
  // movable: every track is removed, not only the moving ones.
  // clearance: the removal box starts this far above the box's bottom, so the road under and
  // around a car stays in the map (a road voxel is often hit only while a car is beside it).
  TrackBoxes(double margin_m, int follow_frames, bool movable, double clearance_m = 0.0);

  void add(int frame, double stamp_s, const std::vector<TrackSnapshot>& tracks);
  // The grown world-frame boxes of the objects to remove at `frame` (stamp_s its time): every
  // track that was ever dynamic (or any track, when movable) and was seen within follow_frames
  // of `frame` on either side.
  std::vector<Box> removalBoxes(int frame, double stamp_s) const;
  // Drops what is older than `frame` - follow_frames (bounded memory).
  void forgetBefore(int frame);
  size_t tracks() const { return tracks_.size(); }

 private:
  struct Sighting {
    double stamp = 0;
    Box box;
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  };
  struct History {
    bool ever_dynamic = false;
    std::map<int, Sighting> seen;  // frame -> box where the track was observed
  };
  double margin_, clearance_;
  int follow_;
  bool movable_;
  std::map<int, History> tracks_;
};

}  // namespace dlslot::mapper
