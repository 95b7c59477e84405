// dlslot-renderer as a process: offline from an LCM log written here with lcm::LogFile, live
// from the same messages over LCM (inside netns-run), and byte-identical images from both.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "dlslot/associations_t.hpp"
#include "dlslot/convert.hpp"
#include "dlslot/detections_t.hpp"
#include "dlslot/ground_truth_t.hpp"
#include "dlslot/odometry_t.hpp"
#include "dlslot/point_cloud_t.hpp"
#include "dlslot/process_status_t.hpp"
#include "dlslot/slot_state_t.hpp"
#include "process_harness.hpp"

namespace dlslot {
namespace {

namespace fs = std::filesystem;
using test::bin;
using test::ChildProcess;

constexpr int kFrames = 5;
constexpr int kMissingFrame = 3;  // no ASSOCIATIONS, no SLOT_STATE: must still render

Pose at(double x, double y) {
  Pose T = Pose::Identity();
  T.translation() = Eigen::Vector3d(x, y, 0);
  return T;
}

struct Event {
  std::string channel;
  std::vector<uint8_t> data;
};

template <class Msg>
Event encoded(const std::string& channel, const Msg& m) {
  Event e{channel, std::vector<uint8_t>(m.getEncodedSize())};
  m.encode(e.data.data(), 0, static_cast<int>(e.data.size()));
  return e;
}

// A small run as the pipeline would publish it: a wall ring, a car 8 m ahead-left moving with
// the ego, the ego driving 1 m per frame along x.
std::vector<Event> smallRun() {
  std::vector<Event> events;
  for (int f = 0; f < kFrames; ++f) {
    const int64_t utime = 1000000 + f * 100000;
    Box car;
    car.center = Eigen::Vector3d(8, 3, -0.9);
    car.size = Eigen::Vector3d(4.2, 1.8, 1.6);
    car.type = "Car";

    PointCloud scan(4, 2400);
    for (int i = 0; i < 2000; ++i) {
      const double a = 2 * M_PI * i / 2000;
      scan.col(i) << static_cast<float>(15 * std::cos(a)), static_cast<float>(15 * std::sin(a)),
          static_cast<float>(-1.5 + 0.001 * i), 0.3f;
    }
    for (int i = 0; i < 400; ++i)
      scan.col(2000 + i) << static_cast<float>(6.5 + 0.0075 * i), static_cast<float>(2.2 + (i % 20) * 0.08f), -0.5f, 0.8f;
    point_cloud_t pc;
    pc.utime = utime;
    pc.frame = f;
    pc.sequence = "test";
    toMsg(scan, pc);
    events.push_back(encoded("LIDAR_SCAN", pc));

    detections_t det{};
    det.utime = utime;
    det.frame = f;
    det.boxes = {toMsg(car)};
    det.num_boxes = 1;
    events.push_back(encoded("DETECTIONS", det));

    ground_truth_t gt;
    gt.utime = utime;
    gt.frame = f;
    gt.has_pose = true;
    gt.pose = toMsg(at(f, 0));
    Box label = car;
    label.id = 1;
    gt.boxes = {toMsg(label)};
    gt.num_boxes = 1;
    gt.num_dontcare = 0;
    events.push_back(encoded("GROUND_TRUTH", gt));

    odometry_t odo{};
    odo.utime = utime;
    odo.frame = f;
    odo.detections_used = true;
    odo.pose = toMsg(at(1.03 * f, 0.05 * f));
    odo.delta = toMsg(Pose::Identity());
    odo.num_points_removed = 400;
    odo.timings = toMsg(StageTimings{{"features", 4.0}, {"scan_to_map", 30.0}, {"total", 40.0}});
    odo.num_timings = static_cast<int32_t>(odo.timings.size());
    events.push_back(encoded("ODOMETRY", odo));
    if (f == 1) events.push_back({"ODOMETRY", {1, 2, 3, 4, 5}});  // garbage: counted, skipped
    if (f == kMissingFrame) continue;

    const Pose ego = at(f + 0.01, 0);
    associations_t as{};
    as.utime = utime;
    as.frame = f;
    as.ego_pose = toMsg(ego);
    as.ego_pose_source = "slot";
    association_t a{};
    a.detection_index = 0;
    a.track_id = 1;
    a.initialized = f >= 2;
    a.box_lidar = toMsg(car);
    a.box_world = toMsg(car.transformed(ego));
    a.has_prediction = f >= 2;
    const Eigen::Vector3d pred = ego * car.center + Eigen::Vector3d(0.3, 0.2, 0);
    for (int k = 0; k < 3; ++k) a.predicted[k] = pred[k];
    a.is_dynamic = true;
    as.associations = {a};
    as.num_associations = 1;
    as.timings = toMsg(StageTimings{{"total", 1.5}});
    as.num_timings = 1;
    events.push_back(encoded("ASSOCIATIONS", as));

    slot_state_t st{};
    st.utime = utime;
    st.frame = f;
    st.mode = "slot";
    st.ego_pose = toMsg(ego);
    st.has_smoothed = f == 4;
    st.smoothed_frame = 0;
    st.smoothed_pose = toMsg(at(0.0, 0.0));
    track_t t{};
    t.id = 1;
    t.type = "Car";
    t.pose = toMsg(ego * car.pose());
    for (int k = 0; k < 3; ++k) t.size[k] = car.size[k];
    t.velocity[0] = 10.0;
    t.is_dynamic = true;
    st.tracks = {t};
    st.num_tracks = 1;
    st.timings = toMsg(StageTimings{{"solve", 8.0}, {"total", 9.0}});
    st.num_timings = 2;
    events.push_back(encoded("SLOT_STATE", st));
  }
  return events;
}

void writeLog(const std::string& path, const std::vector<Event>& events) {
  lcm::LogFile log(path, "w");
  ASSERT_TRUE(log.good());
  int64_t t = 1000000;
  for (const Event& e : events) {
    lcm::LogEvent ev;
    ev.timestamp = t += 1000;
    ev.channel = e.channel;
    ev.datalen = static_cast<int32_t>(e.data.size());
    ev.data = const_cast<uint8_t*>(e.data.data());
    ASSERT_EQ(log.writeEvent(&ev), 0);
  }
}

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

std::vector<std::string> expectedFiles() {
  std::vector<std::string> names;
  for (int f = 0; f < kFrames; ++f) {
    char n[32];
    std::snprintf(n, sizeof n, "%06d.png", f);
    names.push_back(n);
  }
  names.push_back("summary.png");
  return names;
}

void expectImages(const std::string& dir) {
  size_t files = 0;
  for (const auto& e : fs::directory_iterator(dir)) files += e.is_regular_file();
  EXPECT_EQ(files, expectedFiles().size()) << dir;
  for (const std::string& name : expectedFiles()) {
    const cv::Mat img = cv::imread(dir + "/" + name);
    ASSERT_FALSE(img.empty()) << dir << "/" << name;
    EXPECT_EQ(img.cols, name == "summary.png" ? 1600 : 1000) << name;
  }
}

std::string renderOffline(const std::string& log, const std::string& out, const std::string& scratch, int* code) {
  ChildProcess p({bin("dlslot-renderer"), "--config", test::config(), "--log", log, "--out", out},
                 scratch + "/offline-" + fs::path(out).filename().string() + ".txt");
  *code = p.wait(120);
  return p.output();
}

TEST(RendererProcess, OfflineFromALogIsCompleteAndReproducible) {
  ASSERT_TRUE(fs::exists(bin("dlslot-renderer"))) << "build dlslot-renderer first";
  const std::string dir = test::scratchDir();
  const std::string log = dir + "/run.lcmlog";
  writeLog(log, smallRun());

  int code = -1;
  const std::string out = renderOffline(log, dir + "/a", dir, &code);
  ASSERT_EQ(code, 0) << out;
  expectImages(dir + "/a");
  EXPECT_NE(out.find("wrote 5 frames"), std::string::npos) << out;
  EXPECT_NE(out.find("1 undecodable"), std::string::npos) << out;

  ASSERT_EQ((renderOffline(log, dir + "/b", dir, &code), code), 0);
  for (const std::string& name : expectedFiles())
    EXPECT_EQ(slurp(dir + "/a/" + name), slurp(dir + "/b/" + name)) << name << " differs between two renders";
  // The frame without SLOT_STATE differs from its neighbours (no track, a warning).
  EXPECT_NE(slurp(dir + "/a/000003.png"), slurp(dir + "/a/000002.png"));
}

TEST(RendererProcess, BadCommandLineAndLog) {
  const std::string dir = test::scratchDir();
  ChildProcess no_out({bin("dlslot-renderer"), "--config", test::config(), "--log", dir + "/x.lcmlog"}, dir + "/1.txt");
  EXPECT_EQ(no_out.wait(30), 2);
  EXPECT_NE(no_out.output().find("--out"), std::string::npos) << no_out.output();
  ChildProcess no_log({bin("dlslot-renderer"), "--config", test::config(), "--log", dir + "/missing.lcmlog", "--out", dir + "/o"},
                      dir + "/2.txt");
  EXPECT_EQ(no_log.wait(30), 1);
  EXPECT_NE(no_log.output().find("missing.lcmlog"), std::string::npos) << no_log.output();
}

TEST(RendererProcess, LiveRenderMatchesOfflineRender) {
  ASSERT_TRUE(test::insidePrivateNetwork()) << "run through scripts/netns-run (ctest does)";
  const std::string dir = test::scratchDir();
  const std::vector<Event> events = smallRun();
  writeLog(dir + "/run.lcmlog", events);
  int code = -1;
  ASSERT_EQ((renderOffline(dir + "/run.lcmlog", dir + "/offline", dir, &code), code), 0);

  lcm::LCM lcm;
  ASSERT_TRUE(lcm.good());
  bool renderer_up = false;
  lcm.subscribeFunction<process_status_t, bool*>(
      "PROCESS_STATUS", [](const lcm::ReceiveBuffer*, const std::string&, const process_status_t* s, bool* up) {
        if (s->name == "renderer") *up = true;
      }, &renderer_up);
  ChildProcess renderer({bin("dlslot-renderer"), "--config", test::config(), "--out", dir + "/live"}, dir + "/live.txt");
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (!renderer_up && std::chrono::steady_clock::now() < deadline) lcm.handleTimeout(100);
  ASSERT_TRUE(renderer_up) << renderer.output();

  for (const Event& e : events) {
    lcm.publish(e.channel, e.data.data(), static_cast<unsigned>(e.data.size()));
    std::this_thread::sleep_for(std::chrono::milliseconds(20));  // paced like a pipeline
  }
  // Frames 0-3 are drawn as data arrives; the last one after frame_timeout_s without messages.
  const std::string last = dir + "/live/000004.png";
  while (!fs::exists(last) && std::chrono::steady_clock::now() < deadline + std::chrono::seconds(10))
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_TRUE(fs::exists(last)) << renderer.output();
  std::this_thread::sleep_for(std::chrono::milliseconds(200));  // let the write finish
  EXPECT_EQ(renderer.stop(), 0) << renderer.output();
  expectImages(dir + "/live");
  for (const std::string& name : expectedFiles())
    EXPECT_EQ(slurp(dir + "/live/" + name), slurp(dir + "/offline/" + name)) << name << ": live and offline differ";
}

}  // namespace
}  // namespace dlslot
