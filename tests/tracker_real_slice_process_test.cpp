// The whole pipeline (dlslot-run) on the real 30-scan KITTI slice with PointRCNN's Car and
// Pedestrian detection files, inside a private network namespace: a cyclist rides ahead there, and
// PointRCNN puts pedestrian boxes on it. The system's output (SLOT_STATE tracks, tracks_kitti.txt)
// must carry no pedestrian track on the cyclist; the cyclist is tracked, as a cyclist.
#include <gtest/gtest.h>

#include <filesystem>
#include <map>

#include "dlslot/convert.hpp"
#include "dlslot/kitti.hpp"
#include "dlslot/process_status_t.hpp"
#include "dlslot/slot_state_t.hpp"
#include "process_harness.hpp"

using namespace dlslot;
using namespace dlslot::test;
namespace fs = std::filesystem;

namespace {

// Whether the bird's-eye centre `p` lies inside `box` grown by `margin` on every side.
bool inside(const Eigen::Vector2d& p, const Box& box, double margin) {
  const Eigen::Vector2d local = Eigen::Rotation2Dd(-box.yaw) * (p - box.center.head<2>());
  return std::abs(local.x()) <= 0.5 * box.size.x() + margin && std::abs(local.y()) <= 0.5 * box.size.y() + margin;
}

}  // namespace

TEST(TrackerRealSlice, NoPedestrianTrackOnTheCyclist) {
  const std::string root = realDataRoot();
  if (!fs::exists(root + "/detections/pointrcnn_Pedestrian/0000.txt")) GTEST_SKIP() << "no real slice at " << root;
  const std::string out = scratchDir();
  ChildProcess run({bin("dlslot-run"), "--config", config(), "--kitti", root, "--sequence", "0000", "--detections",
                    root + "/detections/pointrcnn_Car", "--detections", root + "/detections/pointrcnn_Pedestrian",
                    "--out", out, "--quiet"},
                   out + "/../real-slice-run.log");
  ASSERT_EQ(run.wait(600), 0) << run.output();

  // The cyclist's box in each scan's lidar frame, from its label.
  const kitti::Calib calib = kitti::readCalib(root + "/training/calib/0000.txt");
  std::map<int, Box> cyclist;
  for (const kitti::LabelRow& r : kitti::readTrackingLabels(root + "/training/label_02/0000.txt"))
    if (r.type == "Cyclist") cyclist[r.frame] = kitti::cameraToLidar(r.box, calib);
  ASSERT_GE(cyclist.size(), 25u);

  // SLOT_STATE: every track of every frame, in that frame's lidar frame (the backend's ego pose).
  int on_cyclist_as_cyclist = 0;
  auto events = readLog(out + "/run.lcmlog");
  const auto states = decodeAll<slot_state_t>(events["SLOT_STATE"]);
  ASSERT_EQ(states.size(), 30u);
  for (const slot_state_t& s : states) {
    const auto c = cyclist.find(s.frame);
    if (c == cyclist.end()) continue;
    const Pose lidar_world = fromMsg(s.ego_pose).inverse();
    for (const track_t& t : s.tracks) {
      if (t.last_seen_frame != s.frame) continue;  // reported this frame
      const Eigen::Vector2d p = (lidar_world * fromMsg(t.pose).translation()).head<2>();
      // Within half a metre of the cyclist's box: the rider and the bicycle.
      if (!inside(p, c->second, 0.5)) continue;
      EXPECT_NE(t.type, "Pedestrian") << "frame " << s.frame << ": pedestrian track " << t.id << " on the cyclist";
      on_cyclist_as_cyclist += t.type == "Cyclist";
    }
  }
  EXPECT_GE(on_cyclist_as_cyclist, 10);  // the cyclist is tracked, under its class

  // tracks_kitti.txt, what the KITTI protocol scores: the same, in the camera frame.
  for (const kitti::LabelRow& r : kitti::readTrackingLabels(out + "/tracks_kitti.txt")) {
    const auto c = cyclist.find(r.frame);
    if (c == cyclist.end() || r.type != "Pedestrian") continue;
    const Box b = kitti::cameraToLidar(r.box, calib);
    EXPECT_FALSE(inside(b.center.head<2>(), c->second, 0.5)) << "frame " << r.frame << ": track " << r.track_id;
  }

  // The decision was the tracker's, counted by reason in its status.
  std::map<std::string, int64_t> counters;
  for (const auto& st : decodeAll<process_status_t>(events["PROCESS_STATUS"]))
    if (st.name == "tracker")
      for (int i = 0; i < st.num_counters; ++i) counters[st.counter_names[i]] = st.counter_values[i];
  EXPECT_GE(counters["tracks_relabelled_too_fast"], 1);
}
