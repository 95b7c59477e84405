// dlslot-foxglove started for real inside the test's network namespace, fed LCM messages, and
// read by npm's `ws` client (tests/js/ws_client.cjs) speaking the Foxglove WebSocket protocol:
// it must advertise every topic, deliver scans (ROS 1 PointCloud2, decoded by Foxglove's own ROS 1
// reader with the advertised definition) and tracks (JSON) to a subscriber, and, for a client
// that stops reading, drop that client's oldest messages (counted in its status) while it goes
// on handling every frame.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdlib>
#include <thread>

#include "dlslot/point_cloud_t.hpp"
#include "dlslot/process_status_t.hpp"
#include "dlslot/slot_state_t.hpp"
#include "process_harness.hpp"

using namespace dlslot;
using namespace dlslot::test;

namespace {

std::string nodeModules() { return binDir() + "/../npm/node_modules"; }

point_cloud_t scan(int frame, int n) {
  point_cloud_t m{};
  m.utime = 1'000'000 + 100'000 * int64_t{frame};
  m.frame = frame;
  m.sequence = "0000";
  m.num_points = n;
  m.x.assign(n, 5.0f);
  m.y.assign(n, 1.0f);
  m.z.assign(n, 0.0f);
  m.intensity.assign(n, 0.3f);
  for (int i = 0; i < n; ++i) m.x[i] += 0.01f * i;
  return m;
}

slot_state_t state(int frame) {
  slot_state_t m{};
  m.utime = scan(frame, 0).utime;
  m.frame = frame;
  m.mode = "slot";
  m.ego_pose.orientation[0] = 1;
  for (int id : {4, 9}) {
    track_t t{};
    t.id = id;
    t.type = "Car";
    t.pose.position[0] = 10 + frame;
    t.pose.orientation[0] = 1;
    t.size[0] = 4, t.size[1] = 2, t.size[2] = 1.5;
    t.velocity[0] = 10;
    t.is_dynamic = true;
    m.tracks.push_back(t);
  }
  m.num_tracks = 2;
  return m;
}

struct Bridge {
  lcm::LCM lcm;
  process_status_t last_status{};
  bool heard = false;
  Subscriptions subs{lcm};
  std::unique_ptr<ChildProcess> proc;
  void onStatus(const lcm::ReceiveBuffer*, const std::string&, const process_status_t* s) {
    if (s->name != "foxglove") return;
    last_status = *s;
    heard = true;
  }
  int64_t counter(const std::string& name) const {
    for (int i = 0; i < last_status.num_counters; ++i)
      if (last_status.counter_names[i] == name) return last_status.counter_values[i];
    return -1;
  }
  Bridge(const std::string& dir, int port, double queue_mb) {
    subs.subscribe("PROCESS_STATUS", &Bridge::onStatus, this);
    proc = std::make_unique<ChildProcess>(
        std::vector<std::string>{bin("dlslot-foxglove"), "--config", config(), "--port", std::to_string(port),
                                 "--queue-mb", std::to_string(queue_mb)},
        dir + "/bridge.log");
    EXPECT_TRUE(handleUntil(lcm, [&] { return heard; }, 15)) << proc->output();
  }
};

// Publishes frames (a scan of `points` and a SLOT_STATE each) every `period_ms` until the client
// exits or `timeout_s` passes; returns the frames published.
int feed(Bridge& b, ChildProcess& client, int points, int period_ms, double timeout_s) {
  int frame = 0;
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (client.running() && std::chrono::steady_clock::now() < end) {
    const point_cloud_t s = scan(frame, points);
    b.lcm.publish("LIDAR_SCAN", &s);
    const slot_state_t st = state(frame);
    b.lcm.publish("SLOT_STATE", &st);
    ++frame;
    const auto next = std::chrono::steady_clock::now() + std::chrono::milliseconds(period_ms);
    while (std::chrono::steady_clock::now() < next) b.lcm.handleTimeout(5);
  }
  return frame;
}

YAML::Node lastJsonLine(const std::string& text) {
  const auto at = text.rfind("\n{");
  return YAML::Load(at == std::string::npos ? text : text.substr(at + 1));
}

TEST(FoxgloveBridge, AdvertisesEveryTopicAndDeliversScansAndTracksToAWsClient) {
  ASSERT_TRUE(insidePrivateNetwork());
  for (const char* package : {"ws", "@foxglove/rosmsg", "@foxglove/rosmsg-serialization"})
    ASSERT_TRUE(std::filesystem::exists(nodeModules() + "/" + package + "/package.json"))
        << "npm's " << package << " is not installed in " << nodeModules() << ": run ./dlslot setup";
  const std::string dir = scratchDir();
  const int port = 18765;
  Bridge bridge(dir, port, 32);
  setenv("NODE_PATH", nodeModules().c_str(), 1);
  ChildProcess client({"/usr/bin/env", "node", sourceDir() + "/tests/js/ws_client.cjs",
                       "ws://127.0.0.1:" + std::to_string(port), "/lidar/points,/slot/tracks,/tf", "5", "20000"},
                      dir + "/client.log");
  feed(bridge, client, 1000, 100, 25);
  EXPECT_EQ(client.wait(5), 0) << client.output();
  const YAML::Node r = lastJsonLine(client.output());
  ASSERT_TRUE(r.IsMap()) << client.output();
  EXPECT_EQ(r["errors"].size(), 0u) << client.output();
  EXPECT_EQ(r["serverInfo"]["name"].as<std::string>(), "dlslot-foxglove");
  const std::map<std::string, std::string> schemas = {
      {"/detections", "foxglove.SceneUpdate"},
      {"/ground_truth/boxes", "foxglove.SceneUpdate"}, {"/ground_truth/path", "foxglove.PosesInFrame"},
      {"/odometry/path", "foxglove.PosesInFrame"},   {"/tracker/associations", "foxglove.SceneUpdate"},
      {"/tf", "foxglove.FrameTransform"},            {"/slot/path", "foxglove.PosesInFrame"},
      {"/slot/tracks", "foxglove.SceneUpdate"},      {"/process_status", "dlslot.ProcessStatus"}};
  for (const auto& [topic, schema] : schemas) {
    EXPECT_EQ(r["advertised"][topic]["schemaName"].as<std::string>(""), schema) << topic;
    EXPECT_EQ(r["advertised"][topic]["encoding"].as<std::string>(""), "json") << topic;
    EXPECT_EQ(r["advertised"][topic]["schemaEncoding"].as<std::string>(""), "jsonschema") << topic;
  }
  // The scan: binary, as ROS 1 PointCloud2, every point and field as published.
  EXPECT_EQ(r["advertised"]["/lidar/points"]["schemaName"].as<std::string>(""), "sensor_msgs/PointCloud2");
  EXPECT_EQ(r["advertised"]["/lidar/points"]["encoding"].as<std::string>(""), "ros1");
  EXPECT_EQ(r["advertised"]["/lidar/points"]["schemaEncoding"].as<std::string>(""), "ros1msg");
  ASSERT_GE(r["topics"]["/lidar/points"]["received"].as<int>(), 5);
  for (const auto& d : r["topics"]["/lidar/points"]["details"]) {
    const int frame = d["seq"].as<int>();
    const point_cloud_t sent = scan(frame, 1000);
    EXPECT_EQ(d["points"].as<int>(), 1000);
    EXPECT_EQ(d["frame_id"].as<std::string>(), "lidar");
    EXPECT_EQ(d["stamp"][0].as<int64_t>(), sent.utime / 1000000) << "frame " << frame;
    EXPECT_EQ(d["stamp"][1].as<int64_t>(), sent.utime % 1000000 * 1000) << "frame " << frame;
    EXPECT_FALSE(d["is_bigendian"].as<bool>());
    EXPECT_TRUE(d["is_dense"].as<bool>());
    ASSERT_EQ(d["fields"].size(), 4u);
    const char* names[4] = {"x", "y", "z", "intensity"};
    for (int f = 0; f < 4; ++f) {
      EXPECT_EQ(d["fields"][f][0].as<std::string>(), names[f]);
      EXPECT_EQ(d["fields"][f][1].as<int>(), 4 * f);
      EXPECT_EQ(d["fields"][f][2].as<int>(), 7);  // FLOAT32
      EXPECT_EQ(d["fields"][f][3].as<int>(), 1);
    }
    for (const auto& [key, i] : {std::pair<const char*, int>{"first", 0}, {"last", 999}}) {
      const float want[4] = {sent.x[i], sent.y[i], sent.z[i], sent.intensity[i]};
      for (int f = 0; f < 4; ++f) EXPECT_EQ(d[key][f].as<float>(), want[f]) << key << " point, field " << names[f];
    }
  }
  ASSERT_GE(r["topics"]["/slot/tracks"]["received"].as<int>(), 5);
  const YAML::Node tracks = r["topics"]["/slot/tracks"]["details"][0];
  EXPECT_EQ(tracks["entities"].as<int>(), 2);
  EXPECT_EQ(tracks["texts"][0].as<std::string>(), "4 Car 10.0 m/s");
  // Its status counts what it sent, and nothing dropped for a client that keeps up.
  bridge.last_status = {};
  ASSERT_TRUE(handleUntil(bridge.lcm, [&] { return bridge.counter("ws_sent") >= 15; }, 5));
  EXPECT_EQ(bridge.counter("ws_dropped_oldest"), 0);
  EXPECT_EQ(bridge.proc->stop(), 0) << bridge.proc->output();
}

TEST(FoxgloveBridge, AClientThatStopsReadingLosesItsOldestMessagesNotThePipelinesTime) {
  ASSERT_TRUE(insidePrivateNetwork());
  const std::string dir = scratchDir();
  const int port = 18766;
  Bridge bridge(dir, port, 2);  // a 2 MB queue: less than two scans of 120k points
  setenv("NODE_PATH", nodeModules().c_str(), 1);
  // The client reads nothing for 4 s, then wants 3 more scans.
  ChildProcess client({"/usr/bin/env", "node", sourceDir() + "/tests/js/ws_client.cjs",
                       "ws://127.0.0.1:" + std::to_string(port), "/lidar/points", "3", "30000", "4000"},
                      dir + "/client.log");
  const int frames = feed(bridge, client, 120000, 50, 30);
  EXPECT_EQ(client.wait(5), 0) << client.output();
  // Every frame was handled while the client stalled: the bridge never waited for it.
  bridge.last_status = {};
  ASSERT_TRUE(handleUntil(bridge.lcm, [&] { return bridge.last_status.frames_handled >= frames; }, 5))
      << "handled " << bridge.last_status.frames_handled << " of " << frames;
  EXPECT_GT(bridge.counter("ws_dropped_oldest"), 0);
  EXPECT_EQ(bridge.proc->stop(), 0) << bridge.proc->output();
}

}  // namespace
