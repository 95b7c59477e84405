// dlslot-tracker started for real, fed over LCM in lockstep like the pipeline does (DETECTIONS
// and ODOMETRY of scan t, then SLOT_STATE of t once ASSOCIATIONS t is out), with a message of
// malformed boxes, an empty scan, a scan whose ODOMETRY never comes, a skipped scan and an undecodable
// message. Runs inside a private network namespace (see tests/CMakeLists.txt).
#include <gtest/gtest.h>

#include <fstream>
#include <limits>

#include "dlslot/associations_t.hpp"
#include "dlslot/convert.hpp"
#include "dlslot/detections_t.hpp"
#include "dlslot/odometry_t.hpp"
#include "dlslot/process_status_t.hpp"
#include "dlslot/slot_state_t.hpp"
#include "dlslot/frame_accounting.hpp"
#include "process_harness.hpp"

using namespace dlslot;
using namespace dlslot::test;

namespace {

struct Listener {
  std::vector<associations_t> associations;
  process_status_t status;
  bool has_status = false;
  void onAssociations(const lcm::ReceiveBuffer*, const std::string&, const associations_t* m) { associations.push_back(*m); }
  void onStatus(const lcm::ReceiveBuffer*, const std::string&, const process_status_t* m) {
    if (m->name != "tracker") return;
    status = *m;
    has_status = true;
  }
};

Pose egoAt(int frame) {
  Pose X = Pose::Identity();
  X.linear() = Eigen::AngleAxisd(0.02 * frame, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  X.translation() << 1.0 * frame, 0.1 * frame, 0;
  return X;
}

}  // namespace

TEST(TrackerProcess, RunsInAPrivateNetwork) { EXPECT_TRUE(insidePrivateNetwork()); }

TEST(TrackerProcess, LockstepFramesWithFaults) {
  const std::string dir = scratchDir();
  ChildProcess tracker({bin("dlslot-tracker"), "--config", configWith(dir, "short-wait", "join_timeout_s: ", "join_timeout_s: 0.4 #")}, dir + "/tracker.out");
  lcm::LCM lcm;
  ASSERT_TRUE(lcm.good());
  Listener listen;
  Subscriptions subs(lcm);
  subs.subscribe("ASSOCIATIONS", &Listener::onAssociations, &listen);
  subs.subscribe("PROCESS_STATUS", &Listener::onStatus, &listen);
  ASSERT_TRUE(handleUntil(lcm, [&] { return listen.has_status; }, 10.0)) << tracker.output();

  // A car at 10 m/s in the world; the ego vehicle drives and turns.
  auto carWorld = [](int f) { return Eigen::Vector3d(15 + 1.0 * f, 4, -0.8); };
  const std::vector<int> frames = {0, 1, 2, 3, 4, 5, 6, 7, 8, 10, 11, 12};  // 9 never comes
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (int f : frames) {
    const Pose X = egoAt(f);
    detections_t det{};
    det.utime = 1000000 + f * 100000;
    det.frame = f;
    if (f != 5) {  // scan 5 has no detections
      Box car;
      car.center = X.inverse() * carWorld(f);
      car.size << 4.2, 1.8, 1.5;
      car.type = "Car";
      car.score = 8.0;  // a confident detector's logit, above the car's min_score
      if (f == 3) {  // first a message of this frame with two malformed boxes before the car:
        // refused whole by the guard (no process publishes such a box), so the real one follows
        detections_t bad_det = det;
        box_t bad = toMsg(car);
        bad.center[1] = nan;
        bad_det.boxes.push_back(bad);
        bad = toMsg(car);
        bad.size[0] = 0;
        bad_det.boxes.push_back(bad);
        bad_det.boxes.push_back(toMsg(car));
        bad_det.num_boxes = static_cast<int32_t>(bad_det.boxes.size());
        lcm.publish("DETECTIONS", &bad_det);
      }
      det.boxes.push_back(toMsg(car));
    }
    det.num_boxes = static_cast<int32_t>(det.boxes.size());
    lcm.publish("DETECTIONS", &det);
    if (f == 4) {
      const uint8_t garbage[7] = {1, 2, 3, 4, 5, 6, 7};
      lcm.publish("DETECTIONS", garbage, sizeof garbage);
    }
    if (f != 7) {  // ODOMETRY of scan 7 never comes: the tracker must time out and go on
      odometry_t odo{};
      odo.utime = det.utime;
      odo.frame = f;
      odo.pose = toMsg(X);
      odo.delta = toMsg(f == 0 ? Pose::Identity() : Pose(egoAt(f - 1).inverse() * X));
      lcm.publish("ODOMETRY", &odo);
    }
    ASSERT_TRUE(handleUntil(lcm, [&] { return !listen.associations.empty() && listen.associations.back().frame == f; }, 5.0))
        << "no ASSOCIATIONS for frame " << f << "\n" << tracker.output();
    // The backend's answer: the true pose (so the next scan's pose is chained from it).
    slot_state_t slot{};
    slot.utime = det.utime;
    slot.frame = f;
    slot.mode = "slot";
    slot.ego_pose = toMsg(X);
    lcm.publish("SLOT_STATE", &slot);
  }
  ASSERT_TRUE(handleUntil(lcm, [&] { return listen.has_status && listen.status.last_frame == 12; }, 3.0));
  const int stop_code = tracker.stop();
  EXPECT_EQ(stop_code, 0) << tracker.output();

  ASSERT_EQ(listen.associations.size(), frames.size());
  int track_id = -1;
  for (size_t i = 0; i < frames.size(); ++i) {
    const associations_t& a = listen.associations[i];
    const int f = frames[i];
    EXPECT_EQ(a.frame, f);
    EXPECT_EQ(a.utime, 1000000 + f * 100000);
    ASSERT_EQ(a.num_timings, 1);
    EXPECT_EQ(a.timings[0].name, "total");
    if (f == 5) {
      EXPECT_EQ(a.num_associations, 0);
      continue;
    }
    ASSERT_EQ(a.num_associations, 1) << f;
    const association_t& as = a.associations[0];
    EXPECT_EQ(as.detection_index, 0);
    EXPECT_EQ(a.num_rejected, 0);
    if (track_id < 0) track_id = as.track_id;
    EXPECT_EQ(as.track_id, track_id) << f;
    EXPECT_EQ(as.box_world.id, track_id);
    // eq. 1 with the ego pose used; exact when that pose is the truth.
    const Pose used = fromMsg(a.ego_pose);
    EXPECT_NEAR((fromMsg(as.box_world).center - used * fromMsg(as.box_lidar).center).norm(), 0, 1e-6);
    if (f == 7) {
      EXPECT_EQ(a.ego_pose_source, "predicted");
    } else {
      EXPECT_EQ(a.ego_pose_source, "odometry");
      EXPECT_NEAR((fromMsg(as.box_world).center - carWorld(f)).norm(), 0, 1e-6) << f;
    }
    EXPECT_EQ(as.initialized, as.num_observations > 3) << f;
    EXPECT_EQ(as.has_prediction, f > 0);
  }
  EXPECT_TRUE(listen.associations.back().associations[0].initialized);
  EXPECT_TRUE(listen.associations.back().associations[0].is_dynamic);

  const process_status_t& s = listen.status;
  EXPECT_EQ(s.frames_handled, static_cast<int64_t>(frames.size()));
  EXPECT_GE(s.decode_errors, 1);
  EXPECT_GE(s.timeouts, 1);
  EXPECT_GE(s.frame_gaps, 1);
  EXPECT_EQ(statusCounter(s, "refused.DETECTIONS.non_finite"), 1);  // the message with the malformed boxes
  EXPECT_EQ(statusCounter(s, "rejected_detections"), 0);
  EXPECT_EQ(statusCounter(s, "odometry_missing"), 1);
  EXPECT_EQ(statusCounter(s, "tracks_started"), 1);
}

TEST(TrackerProcess, BadConfigIsRefused) {
  const std::string dir = scratchDir();
  const std::string path = configWith(dir, "bad", "predictor: polynomial", "predictor: kalman");
  ChildProcess tracker({bin("dlslot-tracker"), "--config", path, "--check-config"}, dir + "/tracker.out");
  EXPECT_EQ(tracker.wait(10), 2);
  EXPECT_NE(tracker.output().find("predictor"), std::string::npos) << tracker.output();
  ChildProcess ok({bin("dlslot-tracker"), "--config", config(), "--check-config"}, dir + "/ok.out");
  EXPECT_EQ(ok.wait(10), 0) << ok.output();
}
