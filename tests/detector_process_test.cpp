// dlslot-detector started for real and fed LIDAR_SCAN over LCM: a ray-cast street gives a Car and
// a Pedestrian in DETECTIONS (source "geometric"), an empty scan an empty DETECTIONS, and a scan
// with a NaN point and an undecodable message are counted in PROCESS_STATUS, never a crash. Runs
// inside a private network namespace (see tests/CMakeLists.txt).
#include <gtest/gtest.h>

#include <fstream>
#include <limits>
#include <sstream>

#include "detector_scene.hpp"
#include "dlslot/convert.hpp"
#include "dlslot/detections_t.hpp"
#include "dlslot/point_cloud_t.hpp"
#include "dlslot/process_status_t.hpp"
#include "dlslot/frame_accounting.hpp"
#include "process_harness.hpp"

using namespace dlslot;
using namespace dlslot::test;

namespace {

struct Listener {
  std::vector<detections_t> detections;
  process_status_t status;
  bool has_status = false;
  void onDetections(const lcm::ReceiveBuffer*, const std::string&, const detections_t* m) { detections.push_back(*m); }
  void onStatus(const lcm::ReceiveBuffer*, const std::string&, const process_status_t* m) {
    if (m->name != "detector") return;
    status = *m;
    has_status = true;
  }
};

point_cloud_t scanMessage(int frame, const PointCloud& cloud) {
  point_cloud_t m;
  m.utime = 1000000 + frame * 100000;
  m.frame = frame;
  m.sequence = "0000";
  toMsg(cloud, m);
  return m;
}

}  // namespace

TEST(DetectorProcess, RunsInAPrivateNetwork) { EXPECT_TRUE(insidePrivateNetwork()); }

TEST(DetectorProcess, ScansInDetectionsOutFaultsCounted) {
  const std::string dir = scratchDir();
  ChildProcess detector({bin("dlslot-detector"), "--config", config()}, dir + "/detector.out");
  lcm::LCM lcm;
  ASSERT_TRUE(lcm.good());
  Listener listen;
  Subscriptions subs(lcm);
  subs.subscribe("DETECTIONS", &Listener::onDetections, &listen);
  subs.subscribe("PROCESS_STATUS", &Listener::onStatus, &listen);
  ASSERT_TRUE(handleUntil(lcm, [&] { return listen.has_status; }, 10.0)) << detector.output();

  DetectorScene street;
  const Box car = street.car(12.0, 4.0, -0.2, 4.2, 1.75, 1.5);
  const Box person = street.place("Pedestrian", 8.0, -3.0, 0.0, 0.7, 0.55, 1.75);
  const PointCloud cloud = street.scan();

  // 0: the street; 1: an empty scan; 2: a NaN point (refused by the guard, no DETECTIONS); then
  // garbage on LIDAR_SCAN; 3: the street again.
  auto waitFor = [&](int frame) {
    return handleUntil(lcm, [&] { return !listen.detections.empty() && listen.detections.back().frame == frame; }, 5.0);
  };
  point_cloud_t m = scanMessage(0, cloud);
  lcm.publish("LIDAR_SCAN", &m);
  ASSERT_TRUE(waitFor(0)) << detector.output() << "status: handled " << listen.status.frames_handled << ", decode errors "
                          << listen.status.decode_errors << ", last warning: " << listen.status.last_warning;
  m = scanMessage(1, PointCloud(4, 0));
  lcm.publish("LIDAR_SCAN", &m);
  ASSERT_TRUE(waitFor(1)) << detector.output();
  m = scanMessage(2, cloud);
  m.z[10] = std::numeric_limits<float>::quiet_NaN();
  lcm.publish("LIDAR_SCAN", &m);
  const uint8_t garbage[9] = {1, 2, 3, 4, 5, 6, 7, 8, 9};
  lcm.publish("LIDAR_SCAN", garbage, sizeof garbage);
  m = scanMessage(3, cloud);
  lcm.publish("LIDAR_SCAN", &m);
  ASSERT_TRUE(waitFor(3)) << detector.output();
  ASSERT_TRUE(handleUntil(lcm, [&] { return listen.status.last_frame == 3 && listen.status.decode_errors >= 1; }, 3.0));
  EXPECT_EQ(detector.stop(), 0) << detector.output();

  ASSERT_EQ(listen.detections.size(), 3u);
  for (const detections_t& d : listen.detections) {
    EXPECT_EQ(d.source, "geometric");
    EXPECT_EQ(d.num_boxes, static_cast<int32_t>(d.boxes.size()));
    EXPECT_EQ(d.utime, 1000000 + d.frame * 100000);
    // Its stages and the whole callback, for the run's timing table (timing_ms.detector.*).
    std::vector<std::string> stages;
    for (const stage_timing_t& t : d.timings) {
      stages.push_back(t.name);
      EXPECT_GE(t.ms, 0.0) << t.name;
    }
    EXPECT_EQ(d.num_timings, static_cast<int32_t>(d.timings.size()));
    EXPECT_EQ(stages, (std::vector<std::string>{"layout", "ground", "clustering", "boxes", "total"}))
        << "frame " << d.frame;
  }
  EXPECT_EQ(listen.detections[1].num_boxes, 0);
  for (const detections_t* d : {&listen.detections[0], &listen.detections[2]}) {
    std::string boxes;
    for (const box_t& b : d->boxes)
      boxes += " " + b.type + " (" + std::to_string(b.center[0]) + ", " + std::to_string(b.center[1]) + ")";
    ASSERT_EQ(d->num_boxes, 2) << "frame " << d->frame << ":" << boxes;
    int found = 0;
    for (const box_t& b : d->boxes) {
      const Box got = fromMsg(b);
      EXPECT_EQ(got.id, -1);
      if (got.type == "Car" && (got.center - car.center).head<2>().norm() < 0.5) ++found;
      if (got.type == "Pedestrian" && (got.center - person.center).head<2>().norm() < 0.3) ++found;
    }
    EXPECT_EQ(found, 2) << "frame " << d->frame;
  }
  const process_status_t& s = listen.status;
  EXPECT_EQ(s.frames_handled, 3);
  EXPECT_GE(s.decode_errors, 1);  // the garbage
  EXPECT_GE(s.errors + s.decode_errors, 2);  // and the NaN scan, refused as a whole
  EXPECT_EQ(statusCounter(s, "boxes_Car"), 2);
  EXPECT_EQ(statusCounter(s, "boxes_Pedestrian"), 2);
}

TEST(DetectorProcess, BadConfigIsRefused) {
  const std::string dir = scratchDir();
  const std::string path = configWith(dir, "bad", "    sectors: 360", "    sectors: 2");
  ChildProcess bad({bin("dlslot-detector"), "--config", path, "--check-config"}, dir + "/bad.out");
  EXPECT_EQ(bad.wait(10), 2);
  EXPECT_NE(bad.output().find("ground.sectors"), std::string::npos) << bad.output();
  ChildProcess ok({bin("dlslot-detector"), "--config", config(), "--check-config"}, dir + "/ok.out");
  EXPECT_EQ(ok.wait(10), 0) << ok.output();
}
