// Collects what the pipeline publishes, frame by frame, and hands out a RenderInput once a frame
// is complete (its SLOT_STATE arrived) or can wait no longer (newer data arrived, or the node's
// timeout). Fed with decoded message contents, it is the same for live and offline rendering,
// so a recorded run renders to the same images.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "render_input.hpp"

namespace dlslot::renderer {

// What SLOT_STATE says about one frame (paper III-C).
struct SlotStateData {
  std::string mode;
  Pose ego_pose = Pose::Identity();      // optimized T_world_lidar of this frame
  std::optional<int> smoothed_frame;     // a frame left the window with this solve...
  Pose smoothed_pose = Pose::Identity();  // ...and this is its final pose
  std::vector<TrackState> tracks;        // trails left empty: RunState fills them
  ModuleTiming timing;
};

// One object's whole path over the run, for the summary image.
struct TrackPath {
  int id = -1;
  std::string type;
  bool is_dynamic = false;  // as last estimated
  Pose last_pose = Pose::Identity();
  Eigen::Vector3d size = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> positions;  // world, one per SLOT_STATE that held the track
};

struct RunSummary {
  int first_frame = -1, last_frame = -1;
  int frames_rendered = 0;
  double duration_s = 0.0;
  // Ego positions by frame (world). DL-SLOT uses each frame's final (smoothed) pose when the
  // frame left the window, else its newest estimate.
  std::map<int, Eigen::Vector3d> odometry_path, slot_path, gt_path;
  std::vector<TrackPath> tracks;  // by id
};

class RunState {
 public:
  RunState(int max_pending_frames = 1, int trail_frames = 30);

  // Each returns false (and counts it as late) when its frame was already drawn; ego poses and
  // track paths are kept even then, for later frames' trajectories and the summary.
  bool addScan(int frame, int64_t utime, PointCloud scan);
  bool addDetections(int frame, int64_t utime, std::vector<Box> detections);
  bool addGroundTruth(int frame, int64_t utime, const std::optional<Pose>& T_world_lidar, std::vector<Box> boxes);
  bool addOdometry(int frame, int64_t utime, const Pose& T_world_lidar, bool filtered, int points_removed,
                   ModuleTiming timing);
  bool addAssociations(int frame, int64_t utime, std::vector<AssociationMark> marks, ModuleTiming timing);
  bool addSlotState(int frame, int64_t utime, SlotStateData state);

  // Frames ready to draw, oldest first: complete, or overtaken by max_pending_frames newer frames
  // or by a newer SLOT_STATE.
  std::vector<RenderInput> takeReady();
  // Every frame still waiting, with whatever layers arrived (timeout, end of log, exit).
  std::vector<RenderInput> takeAll();
  bool hasPending() const { return !pending_.empty(); }

  int64_t lateMessages() const { return late_; }
  int framesWithoutSlotState() const { return frames_without_slot_; }
  RunSummary summary() const;

 private:
  struct Pending {
    int64_t utime = 0;
    RenderInput input;  // layers filled as messages arrive
  };
  Pending* pendingFrame(int frame, int64_t utime);
  RenderInput finish(int frame, Pending&& p);
  Pose slotPoseAsOf(int frame, int as_of) const;

  int max_pending_, trail_frames_;
  std::map<int, Pending> pending_;
  int last_drawn_ = -1;
  int newest_frame_ = -1;
  std::optional<int64_t> first_utime_;
  int64_t late_ = 0;
  int frames_drawn_ = 0, frames_without_slot_ = 0;
  int64_t last_utime_ = 0;

  std::map<int, Pose> odometry_poses_, slot_poses_, gt_poses_;
  struct Smoothed {
    int delivered_at;
    Pose pose;
  };
  std::map<int, Smoothed> smoothed_;
  struct TrackHistory {
    TrackPath path;
    std::vector<int> frames;  // frame of each position
  };
  std::map<int, TrackHistory> tracks_;
};

}  // namespace dlslot::renderer
