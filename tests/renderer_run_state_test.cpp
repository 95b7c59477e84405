// RunState: when a frame is drawn (SLOT_STATE, newer data, timeout/end), what it holds
// (trajectories only up to that frame, smoothed poses once delivered, track trails), late data.
#include <gtest/gtest.h>

#include "run_state.hpp"

namespace dlslot::renderer {
namespace {

Pose at(double x, double y = 0.0) {
  Pose T = Pose::Identity();
  T.translation() = Eigen::Vector3d(x, y, 0);
  return T;
}

PointCloud scanOf(int n) { return PointCloud::Zero(4, n); }

SlotStateData slot(double x, std::vector<TrackState> tracks = {}) {
  SlotStateData s;
  s.mode = "slot";
  s.ego_pose = at(x);
  s.tracks = std::move(tracks);
  s.timing = {"backend", {{"total", 1.0}}};
  return s;
}

TrackState track(int id, double x) {
  TrackState t;
  t.id = id;
  t.type = "Car";
  t.pose = at(x, 5);
  t.size = Eigen::Vector3d(4, 2, 1.5);
  return t;
}

TEST(RendererRunState, FrameIsReadyWhenItsSlotStateArrives) {
  RunState s(1, 30);
  s.addScan(0, 1000000, scanOf(10));
  s.addDetections(0, 1000000, {});
  s.addOdometry(0, 1000000, at(0), true, 0, {"odometry", {{"total", 50.0}}});
  EXPECT_TRUE(s.takeReady().empty());
  s.addAssociations(0, 1000000, {}, {"tracker", {{"total", 2.0}}});
  s.addSlotState(0, 1000000, slot(0.0, {track(1, 10)}));
  std::vector<RenderInput> r = s.takeReady();
  ASSERT_EQ(r.size(), 1u);
  const RenderInput& in = r[0];
  EXPECT_EQ(in.frame, 0);
  EXPECT_TRUE(in.has_scan && in.has_detections && in.has_odometry && in.has_associations && in.has_tracks);
  EXPECT_FALSE(in.has_ground_truth);
  EXPECT_EQ(in.scan.cols(), 10);
  EXPECT_EQ(in.ego_source, "DL-SLOT");
  ASSERT_EQ(in.timings.size(), 3u);  // pipeline order whatever the arrival order
  EXPECT_EQ(in.timings[0].module, "odometry");
  EXPECT_EQ(in.timings[1].module, "tracker");
  EXPECT_EQ(in.timings[2].module, "backend");
  EXPECT_FALSE(s.hasPending());
}

TEST(RendererRunState, NextScanForcesAFrameWithMissingLayers) {
  RunState s(1, 30);
  s.addScan(0, 0, scanOf(5));
  s.addOdometry(0, 0, at(0), true, 0, {"odometry", {}});
  EXPECT_TRUE(s.takeReady().empty());
  s.addScan(1, 100000, scanOf(5));  // frame 0's SLOT_STATE never came
  std::vector<RenderInput> r = s.takeReady();
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].frame, 0);
  EXPECT_FALSE(r[0].has_tracks);
  EXPECT_EQ(r[0].ego_source, "odometry");
  EXPECT_EQ(s.framesWithoutSlotState(), 1);
  // The late SLOT_STATE is refused (counted) but its pose still feeds the trajectory.
  EXPECT_FALSE(s.addSlotState(0, 0, slot(0.1)));
  EXPECT_EQ(s.lateMessages(), 1);
  // Timeout / end of log: whatever is there.
  r = s.takeAll();
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].frame, 1);
  EXPECT_FALSE(r[0].ego_pose.has_value());
  ASSERT_EQ(r[0].slot_path.size(), 1u);
  EXPECT_DOUBLE_EQ(r[0].slot_path[0].x(), 0.1);
  EXPECT_DOUBLE_EQ(r[0].time_s, 0.1);
}

TEST(RendererRunState, MorePendingFramesWaitLonger) {
  RunState s(3, 30);
  for (int f = 0; f < 3; ++f) s.addScan(f, f, scanOf(1));
  EXPECT_TRUE(s.takeReady().empty());
  s.addScan(3, 3, scanOf(1));
  EXPECT_EQ(s.takeReady().size(), 1u);
  // A SLOT_STATE releases its frame and every older one.
  s.addSlotState(2, 2, slot(2));
  std::vector<RenderInput> r = s.takeReady();
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[0].frame, 1);
  EXPECT_EQ(r[1].frame, 2);
}

TEST(RendererRunState, TrajectoriesStopAtTheDrawnFrameAndUseSmoothedPoses) {
  RunState s(5, 2);
  for (int f = 0; f < 4; ++f) {
    s.addGroundTruth(f, f, at(f), {});
    s.addOdometry(f, f, at(f + 0.5), true, 0, {"odometry", {}});
    SlotStateData st = slot(f + 0.25, {track(7, 10.0 + f)});
    if (f == 3) {  // frame 0 leaves the window with its final pose
      st.smoothed_frame = 0;
      st.smoothed_pose = at(-1.0);
    }
    s.addSlotState(f, f, std::move(st));
  }
  // With 5 pending frames allowed, the newest SLOT_STATE (frame 3) releases frames 0-3 at once.
  std::vector<RenderInput> r = s.takeReady();
  ASSERT_EQ(r.size(), 4u);
  const RenderInput& f1 = r[1];
  ASSERT_EQ(f1.gt_path.size(), 2u);
  ASSERT_EQ(f1.odometry_path.size(), 2u);
  ASSERT_EQ(f1.slot_path.size(), 2u);
  EXPECT_DOUBLE_EQ(f1.slot_path[0].x(), 0.25);  // the smoothed pose came later (frame 3)
  EXPECT_DOUBLE_EQ(f1.odometry_path[1].x(), 1.5);
  const RenderInput& f3 = r[3];
  ASSERT_EQ(f3.slot_path.size(), 4u);
  EXPECT_DOUBLE_EQ(f3.slot_path[0].x(), -1.0);  // delivered by frame 3
  EXPECT_DOUBLE_EQ(f3.ego_pose->translation().x(), 3.25);
  // Trail: the last 2 frames before this one.
  ASSERT_EQ(f3.tracks.size(), 1u);
  ASSERT_EQ(f3.tracks[0].trail.size(), 2u);
  EXPECT_DOUBLE_EQ(f3.tracks[0].trail[0].x(), 11.0);
  EXPECT_DOUBLE_EQ(f3.tracks[0].trail[1].x(), 12.0);

  const RunSummary sum = s.summary();
  EXPECT_EQ(sum.first_frame, 0);
  EXPECT_EQ(sum.last_frame, 3);
  EXPECT_EQ(sum.frames_rendered, 4);
  EXPECT_DOUBLE_EQ(sum.slot_path.at(0).x(), -1.0);
  ASSERT_EQ(sum.tracks.size(), 1u);
  EXPECT_EQ(sum.tracks[0].positions.size(), 4u);
}

}  // namespace
}  // namespace dlslot::renderer
