// The player started for real, recorded with lcm-logger, replayed with lcm-logplayer, read back
// with lcm::LogFile. Runs inside a private network namespace (see tests/CMakeLists.txt).
#include <gtest/gtest.h>

#include <filesystem>
#include <random>
#include <thread>

#include "dlslot/convert.hpp"
#include "dlslot/detections_t.hpp"
#include "dlslot/ground_truth_t.hpp"
#include "dlslot/kitti.hpp"
#include "dlslot/point_cloud_t.hpp"
#include "dlslot/process_status_t.hpp"
#include "process_harness.hpp"

using namespace dlslot;
using namespace dlslot::test;
namespace fs = std::filesystem;

namespace {

// A tiny KITTI tracking sequence: frame i has 1000 + 100 i random points, one detection and one label.
struct TinySequence {
  std::string root;
  int frames = 6;
  kitti::Calib calib;
  explicit TinySequence(const std::string& dir) : root(dir + "/kitti") {
    const fs::path t = fs::path(root) / "training";
    for (auto sub : {"velodyne/0000", "calib", "label_02", "det"}) fs::create_directories(t / sub);
    calib.T_cam_velo.linear() << 0, -1, 0, 0, 0, -1, 1, 0, 0;
    calib.T_cam_velo.translation() << 0, -0.08, -0.27;
    kitti::writeCalib((t / "calib/0000.txt").string(), calib);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-20, 20);
    std::vector<kitti::LabelRow> labels, dets;
    for (int i = 0; i < frames; ++i) {
      PointCloud scan(4, 1000 + 100 * i);
      for (Eigen::Index k = 0; k < scan.cols(); ++k) scan.col(k) << u(rng), u(rng), u(rng) / 10, 0.5f;
      char name[32];
      std::snprintf(name, sizeof name, "%06d.bin", i);
      kitti::writeVelodyne((t / "velodyne/0000" / name).string(), scan);
      Box b;
      b.center << 10 + i, 2, -0.9;
      b.size << 4, 1.8, 1.5;
      b.yaw = 0.1 * i;
      kitti::LabelRow r;
      r.frame = i;
      r.track_id = 3;
      r.type = "Car";
      r.box = kitti::lidarToCamera(b, calib);
      labels.push_back(r);
      r.track_id = -1;
      r.score = 0.9;
      dets.push_back(r);
    }
    kitti::writeTrackingLabels((t / "label_02/0000.txt").string(), labels);
    kitti::writeTrackingLabels((t / "det/0000.txt").string(), dets);
  }
  std::string detections() const { return root + "/training/det/0000.txt"; }
};

std::vector<std::string> playerArgs(const std::string& root, const std::string& seq, std::vector<std::string> extra) {
  std::vector<std::string> a = {bin("dlslot-player"), "--config", config(), "--kitti", root, "--sequence", seq,
                                "--quiet", "--delay", "0.3"};
  a.insert(a.end(), extra.begin(), extra.end());
  return a;
}

// Records everything on the bus into `log` while `body` runs.
template <class F>
void recorded(const std::string& dir, const std::string& log, F body) {
  ChildProcess logger({"/usr/bin/lcm-logger", "--quiet", "--force", log}, dir + "/logger.out");
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  body();
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  ASSERT_EQ(logger.stop(), 0) << logger.output();
}

}  // namespace

TEST(PlayerProcess, RunsInAPrivateNetwork) { EXPECT_TRUE(insidePrivateNetwork()); }

TEST(PlayerProcess, RateModeRecordedLogHasEveryFrameOnceInOrder) {
  const std::string dir = scratchDir();
  TinySequence seq(dir);
  const std::string log = dir + "/run.lcmlog";
  recorded(dir, log, [&] {
    ChildProcess player(playerArgs(seq.root, "0000", {"--detections", seq.detections(), "--speed", "5"}), dir + "/player.out");
    ASSERT_EQ(player.wait(30), 0) << player.output();
  });
  auto events = readLog(log);
  const auto scans = decodeAll<point_cloud_t>(events["LIDAR_SCAN"]);
  const auto dets = decodeAll<detections_t>(events["DETECTIONS"]);
  const auto gts = decodeAll<ground_truth_t>(events["GROUND_TRUTH"]);
  ASSERT_EQ(static_cast<int>(scans.size()), seq.frames);
  ASSERT_EQ(static_cast<int>(dets.size()), seq.frames);
  ASSERT_EQ(static_cast<int>(gts.size()), seq.frames);
  EXPECT_FALSE(events["PROCESS_STATUS"].empty());
  for (int i = 0; i < seq.frames; ++i) {
    EXPECT_EQ(scans[i].frame, i);
    EXPECT_EQ(scans[i].num_points, 1000 + 100 * i);
    EXPECT_EQ(scans[i].utime, i * 100000);
    ASSERT_EQ(dets[i].num_boxes, 1);
    // Detections arrive in the lidar frame: the box we wrote in camera coordinates comes back.
    EXPECT_NEAR(dets[i].boxes[0].center[0], 10 + i, 1e-4);
    EXPECT_NEAR(dets[i].boxes[0].center[1], 2, 1e-4);
    EXPECT_NEAR(dets[i].boxes[0].center[2], -0.9, 1e-4);
    EXPECT_NEAR(dets[i].boxes[0].yaw, 0.1 * i, 1e-5);
    EXPECT_EQ(dets[i].boxes[0].id, -1);
    ASSERT_EQ(gts[i].num_boxes, 1);
    EXPECT_EQ(gts[i].boxes[0].id, 3);
    EXPECT_FALSE(gts[i].has_pose);
  }

  // Replay with lcm-logplayer: a second recording receives the same messages.
  const std::string replay_log = dir + "/replay.lcmlog";
  recorded(dir, replay_log, [&] {
    ChildProcess logplayer({"/usr/bin/lcm-logplayer", "--speed=4", log}, dir + "/logplayer.out");
    ASSERT_EQ(logplayer.wait(30), 0) << logplayer.output();
  });
  auto replayed = readLog(replay_log);
  for (const std::string ch : {"LIDAR_SCAN", "DETECTIONS", "GROUND_TRUTH"}) {
    ASSERT_EQ(replayed[ch].size(), events[ch].size()) << ch;
    for (size_t i = 0; i < events[ch].size(); ++i) EXPECT_EQ(replayed[ch][i], events[ch][i]) << ch << " " << i;
  }
}

TEST(PlayerProcess, LockstepWaitsForTheConsumerAndReportsTimeouts) {
  const std::string dir = scratchDir();
  TinySequence seq(dir);
  // A small consumer: acknowledges each scan on ACK after 50 ms, but never frame 2.
  lcm::LCM lcm;
  ASSERT_TRUE(lcm.good());
  std::vector<int> seen;
  int last_acked = -1;
  bool overtaken = false;
  struct Ctx {
    lcm::LCM* lcm;
    std::vector<int>* seen;
    int* last_acked;
    bool* overtaken;
  } ctx{&lcm, &seen, &last_acked, &overtaken};
  lcm.subscribeFunction<Ctx*>(
      "LIDAR_SCAN",
      [](const lcm::ReceiveBuffer* rbuf, const std::string&, Ctx* c) {
        point_cloud_t scan;
        if (scan.decode(rbuf->data, 0, rbuf->data_size) < 0) return;
        // The player must not publish frame t+1 before frame t was acknowledged (2 is the timeout case).
        if (!c->seen->empty() && c->seen->back() != 2 && *c->last_acked != c->seen->back()) *c->overtaken = true;
        c->seen->push_back(scan.frame);
        if (scan.frame == 2) return;
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
        detections_t ack{};
        ack.utime = scan.utime;
        ack.frame = scan.frame;
        ack.num_boxes = 0;
        c->lcm->publish("ACK", &ack);
        *c->last_acked = scan.frame;
      },
      &ctx);
  const std::string log = dir + "/run.lcmlog";
  std::string out;
  recorded(dir, log, [&] {
    ChildProcess player(playerArgs(seq.root, "0000", {"--lockstep", "ACK"}), dir + "/player.out");
    while (player.running()) lcm.handleTimeout(50);
    EXPECT_EQ(player.wait(1), 0) << player.output();
    out = player.output();
  });
  EXPECT_EQ(seen, std::vector<int>({0, 1, 2, 3, 4, 5}));
  EXPECT_FALSE(overtaken);
  EXPECT_NE(out.find("ACK did not carry frame 2"), std::string::npos) << out;
  const auto status = decodeAll<process_status_t>(readLog(log)["PROCESS_STATUS"]);
  ASSERT_FALSE(status.empty());
  EXPECT_EQ(status.back().timeouts, 1);
  EXPECT_EQ(status.back().frames_handled, seq.frames);
}

TEST(PlayerProcess, BadInputExitsNonZeroWithAClearMessage) {
  const std::string dir = scratchDir();
  ChildProcess missing(playerArgs("/nonexistent/kitti", "0000", {}), dir + "/missing.out");
  EXPECT_EQ(missing.wait(10), 1);
  EXPECT_NE(missing.output().find("/nonexistent/kitti: data set root is not a directory"), std::string::npos)
      << missing.output();
  ChildProcess bad_opt(playerArgs("/tmp", "0000", {"--speed", "fast"}), dir + "/badopt.out");
  EXPECT_EQ(bad_opt.wait(10), 2);
  EXPECT_NE(bad_opt.output().find("--speed: expected a number, got 'fast'"), std::string::npos) << bad_opt.output();
}

// Real data: 30 scans with the files' point counts; every labelled car contains scan points.
TEST(PlayerProcess, PlaysTheRealKittiSlice) {
  const std::string root = realDataRoot();
  if (!fs::exists(root)) GTEST_SKIP() << "real data slice not present at " << root;
  const std::string dir = scratchDir();
  const std::string log = dir + "/real.lcmlog";
  recorded(dir, log, [&] {
    ChildProcess player(playerArgs(root, "0000", {"--speed", "2", "--detections", root + "/detections/pointrcnn_Car"}),
                        dir + "/player.out");
    ASSERT_EQ(player.wait(60), 0) << player.output();
  });
  auto events = readLog(log);
  const auto scans = decodeAll<point_cloud_t>(events["LIDAR_SCAN"]);
  const auto gts = decodeAll<ground_truth_t>(events["GROUND_TRUTH"]);
  ASSERT_EQ(scans.size(), 30u);
  ASSERT_EQ(gts.size(), 30u);
  int cars = 0;
  for (int i = 0; i < 30; ++i) {
    char name[64];
    std::snprintf(name, sizeof name, "/training/velodyne/0000/%06d.bin", i);
    EXPECT_EQ(scans[i].frame, i);
    EXPECT_EQ(static_cast<uintmax_t>(scans[i].num_points) * 16, fs::file_size(root + name));
    const PointCloud scan = fromMsg(scans[i]);
    for (const box_t& m : gts[i].boxes) {
      const Box b = fromMsg(m);
      if ((b.type != "Car" && b.type != "Van") || b.center.head<2>().norm() > 40) continue;
      int inside = 0;
      for (Eigen::Index k = 0; k < scan.cols(); ++k) inside += b.contains(scan.col(k).head<3>().cast<double>());
      EXPECT_GT(inside, 10) << "frame " << i << " track " << b.id;
      ++cars;
    }
  }
  EXPECT_GT(cars, 20);
}
