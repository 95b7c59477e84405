// dlslot-odometry started for real over LCM in a private network namespace (see
// tests/CMakeLists.txt): behind dlslot-player in lockstep on a short simulated sequence (every
// frame answered, drift within bounds), and fed directly with faults (undecodable message,
// malformed box, missing DETECTIONS, empty scan).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "dlslot/convert.hpp"
#include "dlslot/detections_t.hpp"
#include "dlslot/kitti.hpp"
#include "dlslot/odometry_t.hpp"
#include "dlslot/point_cloud_t.hpp"
#include "dlslot/process_status_t.hpp"
#include "odometry_scene.hpp"
#include "dlslot/frame_accounting.hpp"
#include "process_harness.hpp"

using namespace dlslot;
using namespace dlslot::test;

namespace {

struct Listener {
  std::vector<odometry_t> odometry;
  process_status_t status;
  bool has_status = false;
  void onOdometry(const lcm::ReceiveBuffer*, const std::string&, const odometry_t* m) { odometry.push_back(*m); }
  void onStatus(const lcm::ReceiveBuffer*, const std::string&, const process_status_t* m) {
    if (m->name != "odometry") return;
    status = *m;
    has_status = true;
  }
};

}  // namespace

TEST(OdometryProcess, RunsInAPrivateNetwork) { EXPECT_TRUE(insidePrivateNetwork()); }

TEST(OdometryProcess, BehindThePlayerOnASimulatedSequence) {
  for (const char* tool : {"dlslot-sim", "dlslot-player"}) ASSERT_TRUE(std::filesystem::exists(bin(tool))) << bin(tool);
  const std::string dir = scratchDir();
  const int frames = 40;
  ChildProcess sim({bin("dlslot-sim"), "--scenario", "urban-static", "--out", dir + "/sim", "--frames",
                    std::to_string(frames), "--threads", "1"},
                   dir + "/sim.out");
  ASSERT_EQ(sim.wait(300), 0) << sim.output();

  ChildProcess odometry({bin("dlslot-odometry"), "--config", config()}, dir + "/odometry.out");
  lcm::LCM lcm;
  ASSERT_TRUE(lcm.good());
  Listener listen;
  Subscriptions subs(lcm);
  subs.subscribe("ODOMETRY", &Listener::onOdometry, &listen);
  subs.subscribe("PROCESS_STATUS", &Listener::onStatus, &listen);
  ASSERT_TRUE(handleUntil(lcm, [&] { return listen.has_status; }, 10.0)) << odometry.output();

  ChildProcess player({bin("dlslot-player"), "--config", config(), "--kitti", dir + "/sim", "--sequence", "0000",
                       "--detections", dir + "/sim/detections/sim/0000.txt", "--lockstep", "ODOMETRY", "--quiet",
                       "--delay", "0.5"},
                      dir + "/player.out");
  ASSERT_TRUE(handleUntil(lcm, [&] { return !listen.odometry.empty() && listen.odometry.back().frame == frames - 1; },
                          240.0))
      << odometry.output() << player.output();
  EXPECT_EQ(player.wait(10), 0) << player.output();
  EXPECT_EQ(odometry.stop(), 0) << odometry.output();

  // Every frame answered once, in order, and registered with the detected objects removed.
  ASSERT_EQ(listen.odometry.size(), static_cast<size_t>(frames));
  const kitti::SequenceReader truth(dir + "/sim", "0000");
  ASSERT_TRUE(truth.hasGroundTruthPoses());
  const std::vector<Pose>& gt = truth.groundTruthPoses();
  double path = 0;
  for (int i = 0; i < frames; ++i) {
    const odometry_t& m = listen.odometry[i];
    EXPECT_EQ(m.frame, i);
    EXPECT_EQ(m.status, i == 0 ? +odometry_t::STATUS_FIRST_FRAME : +odometry_t::STATUS_OK) << m.status_text;
    EXPECT_TRUE(m.detections_used);
    ASSERT_EQ(m.num_timings, 4);
    EXPECT_EQ(m.timings[3].name, "total");
    if (i > 0) path += (gt[i].translation() - gt[i - 1].translation()).norm();
    // Drift: within 1 % of the distance driven (plus 5 cm).
    const Pose truth_i = gt[0].inverse() * gt[i];
    EXPECT_LT((fromMsg(m.pose).translation() - truth_i.translation()).norm(), 0.05 + 0.01 * path) << "frame " << i;
  }
  EXPECT_GT(path, 10.0);
  int removed = 0;
  for (const odometry_t& m : listen.odometry) removed += m.num_points_removed;
  EXPECT_GT(removed, 0);
}

TEST(OdometryProcess, FaultsDoNotStopIt) {
  const std::string dir = scratchDir();
  ChildProcess odometry({bin("dlslot-odometry"), "--config", configWith(dir, "short-wait", "detections_timeout_s: ", "detections_timeout_s: 0.4 #")}, dir + "/odometry.out");
  lcm::LCM lcm;
  ASSERT_TRUE(lcm.good());
  Listener listen;
  Subscriptions subs(lcm);
  subs.subscribe("ODOMETRY", &Listener::onOdometry, &listen);
  subs.subscribe("PROCESS_STATUS", &Listener::onStatus, &listen);
  ASSERT_TRUE(handleUntil(lcm, [&] { return listen.has_status; }, 10.0)) << odometry.output();

  const odometry::test::Scene street = odometry::test::street();
  Box car;
  car.center << 30, -3, -1;
  car.size << 4, 1.8, 1.5;
  car.type = "Car";
  for (int f = 0; f < 5; ++f) {
    point_cloud_t scan;
    scan.utime = 1000000 + f * 100000;
    scan.frame = f;
    scan.sequence = "test";
    toMsg(f == 3 ? PointCloud(4, 0) : street.scan(odometry::test::planarPose(1.0 * f, 0, 0)), scan);
    lcm.publish("LIDAR_SCAN", &scan);
    if (f == 1) {
      const uint8_t garbage[9] = {9, 8, 7, 6, 5, 4, 3, 2, 1};
      lcm.publish("LIDAR_SCAN", garbage, sizeof garbage);
    }
    if (f != 2) {  // DETECTIONS of scan 2 never come
      detections_t det{};
      det.utime = scan.utime;
      det.frame = f;
      det.boxes.push_back(toMsg(car));
      if (f == 1) {  // first a copy with a malformed box: refused whole by the guard
        detections_t bad_det = det;
        box_t bad = toMsg(car);
        bad.size[2] = -1;
        bad_det.boxes.push_back(bad);
        bad_det.num_boxes = static_cast<int32_t>(bad_det.boxes.size());
        lcm.publish("DETECTIONS", &bad_det);
      }
      det.num_boxes = static_cast<int32_t>(det.boxes.size());
      lcm.publish("DETECTIONS", &det);
    }
    ASSERT_TRUE(handleUntil(lcm, [&] { return !listen.odometry.empty() && listen.odometry.back().frame == f; }, 10.0))
        << "no ODOMETRY for frame " << f << "\n" << odometry.output();
  }
  ASSERT_TRUE(handleUntil(lcm, [&] { return listen.status.last_frame == 4; }, 3.0));
  EXPECT_TRUE(odometry.running());
  EXPECT_EQ(odometry.stop(), 0) << odometry.output();

  ASSERT_EQ(listen.odometry.size(), 5u);
  const auto& o = listen.odometry;
  EXPECT_EQ(o[0].status, +odometry_t::STATUS_FIRST_FRAME);
  EXPECT_TRUE(o[1].detections_used);
  EXPECT_EQ(o[1].status, +odometry_t::STATUS_OK) << o[1].status_text;
  EXPECT_FALSE(o[2].detections_used);  // ran unfiltered, and says so
  EXPECT_NE(o[2].status_text.find("timed out"), std::string::npos) << o[2].status_text;
  EXPECT_EQ(o[3].status, +odometry_t::STATUS_FALLBACK_FEW_POINTS);
  EXPECT_EQ(o[4].status, +odometry_t::STATUS_OK) << o[4].status_text;
  EXPECT_NEAR(fromMsg(o[4].pose).translation().x(), 4.0, 0.1);
  const process_status_t& s = listen.status;
  EXPECT_EQ(s.frames_handled, 5);
  EXPECT_GE(s.decode_errors, 1);
  EXPECT_GE(s.errors, 1);
  EXPECT_GE(s.timeouts, 1);
  EXPECT_EQ(statusCounter(s, "unfiltered_frames"), 1);
  EXPECT_EQ(statusCounter(s, "fallback_frames"), 1);
  EXPECT_EQ(statusCounter(s, "refused.DETECTIONS.bad_size"), 1);
  EXPECT_EQ(statusCounter(s, "rejected_detections"), 0);
}
