// The backend node without a network: the frame joiner, the offline driver (an LCM log with
// ODOMETRY + ASSOCIATIONS in, SLOT_STATE out) and its command line.
#include <gtest/gtest.h>

#include <cstdlib>

#include "dlslot/frame_joiner.hpp"
#include "backend_scene.hpp"
#include "backend_test_messages.hpp"
#include "dlslot/convert.hpp"
#include "dlslot/kitti.hpp"
#include "dlslot/slot_state_t.hpp"
#include "process_harness.hpp"

using namespace dlslot;
using namespace dlslot::backend;
using namespace dlslot::backend::test;
using dlslot::test::bin;
using dlslot::test::ChildProcess;
using dlslot::test::config;
using dlslot::test::decodeAll;
using dlslot::test::readLog;
using dlslot::test::scratchDir;

TEST(BackendFrameJoiner, JoinsByFrameAndTimesOut) {
  FrameJoiner<int, std::string> j(1.0);
  EXPECT_TRUE(j.addA(0, 10, 0.0));
  EXPECT_TRUE(j.release(0.5).empty());  // waiting for B
  EXPECT_TRUE(j.addB(0, "zero", 0.6));
  auto out = j.release(0.6);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].frame, 0);
  EXPECT_EQ(*out[0].a, 10);
  EXPECT_EQ(*out[0].b, "zero");
  // Frame 1 never gets its B: released after the timeout with B missing.
  j.addA(1, 11, 1.0);
  EXPECT_TRUE(j.release(1.9).empty());
  out = j.release(2.0);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_FALSE(out[0].b.has_value());
  // A late B for a released frame is refused.
  EXPECT_FALSE(j.addB(1, "late", 2.1));
  // Frame 2 lacks A, frame 3 is complete: 2 goes first, without waiting for its timeout.
  j.addB(2, "two", 3.0);
  j.addA(3, 13, 3.0);
  j.addB(3, "three", 3.0);
  out = j.release(3.0);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].frame, 2);
  EXPECT_FALSE(out[0].a.has_value());
  EXPECT_EQ(out[1].frame, 3);
  j.addA(5, 15, 4.0);
  EXPECT_EQ(j.flush().size(), 1u);
  EXPECT_EQ(j.pending(), 0u);
}

namespace {

// Writes a scene's inputs as the odometry and the tracker would publish them.
void writeLog(const std::string& path, const std::vector<BackendInput>& inputs) {
  lcm::LogFile log(path, "w");
  ASSERT_TRUE(log.good());
  int64_t n = 0;
  auto write = [&](const std::string& channel, const auto& msg, int64_t utime) {
    std::vector<uint8_t> buf(msg.getEncodedSize());
    msg.encode(buf.data(), 0, static_cast<int>(buf.size()));
    lcm::LogEvent ev;
    ev.eventnum = n++;
    ev.timestamp = utime;
    ev.channel = channel;
    ev.datalen = static_cast<int32_t>(buf.size());
    ev.data = buf.data();
    ASSERT_EQ(log.writeEvent(&ev), 0);
  };
  for (const BackendInput& in : inputs) {
    if (in.odometry) write("ODOMETRY", odometryMsg(in), in.utime);
    if (!in.associations_missing) write("ASSOCIATIONS", associationsMsg(in), in.utime + 1);
  }
}


}  // namespace

TEST(BackendNode, OfflineReplayWritesSlotState) {
  const std::string dir = scratchDir();
  const SimScene scene = parkedAndMovingScene(7, 9);
  const auto inputs = scene.generate(25);
  writeLog(dir + "/in.lcmlog", inputs);
  for (const std::string mode : {"slot", "two-stage", "odometry-only"}) {
    const std::string out_path = dir + "/out-" + mode + ".lcmlog";
    ChildProcess p({bin("dlslot-backend"), "--config", config(), "--offline", dir + "/in.lcmlog", "--out", out_path,
                    "--mode", mode},
                   dir + "/backend-" + mode + ".txt");
    ASSERT_EQ(p.wait(120), 0) << p.output();
    EXPECT_NE(p.output().find("25 frames, 1 without odometry, 1 without associations"), std::string::npos) << p.output();
    auto events = readLog(out_path);
    // The input run is copied, with this run's SLOT_STATE added.
    EXPECT_EQ(events["ODOMETRY"].size(), 24u);
    EXPECT_EQ(events["ASSOCIATIONS"].size(), 24u);
    const auto states = decodeAll<slot_state_t>(events["SLOT_STATE"]);
    ASSERT_EQ(states.size(), 25u);
    for (size_t t = 0; t < states.size(); ++t) {
      const slot_state_t& s = states[t];
      EXPECT_EQ(s.frame, static_cast<int>(t));
      EXPECT_EQ(s.utime, inputs[t].utime);
      EXPECT_EQ(s.mode, mode);
      EXPECT_EQ(s.odometry_missing, t == 7);
      EXPECT_EQ(s.associations_missing, t == 9);
      EXPECT_EQ(s.has_smoothed, t >= 9);  // window of 10
      if (s.has_smoothed) {
        EXPECT_EQ(s.smoothed_frame, static_cast<int>(t) - 9);
      }
      std::vector<std::string> stages;
      for (const auto& st : s.timings) stages.push_back(st.name);
      EXPECT_NE(std::find(stages.begin(), stages.end(), "solve"), stages.end());
      EXPECT_NE(std::find(stages.begin(), stages.end(), "marginalize"), stages.end());
      EXPECT_NE(std::find(stages.begin(), stages.end(), "total"), stages.end());
    }
    const slot_state_t& last = states.back();
    EXPECT_LT((fromMsg(last.ego_pose).translation() - scene.egoTruth(24).translation()).norm(), 1.0);
    if (mode == "odometry-only") {
      EXPECT_EQ(last.num_tracks, 0);
      continue;
    }
    ASSERT_EQ(last.num_tracks, 2);
    for (const track_t& tr : last.tracks) {
      EXPECT_EQ(tr.is_dynamic, tr.id == 2) << tr.id;
      EXPECT_EQ(tr.age, 24);
      EXPECT_EQ(tr.type, "Car");
      if (tr.id == 2) {
        EXPECT_NEAR(std::hypot(tr.velocity[0], tr.velocity[1]), 12.0, 1.0);
      }
      if (mode == "slot") {
        EXPECT_GT(tr.covariance[0], 0.0);
      }
    }
    if (mode == "slot") {
      EXPECT_GT(last.ego_covariance[0], 0.0);
      EXPECT_GT(last.iterations, 0);
      EXPECT_LE(last.final_cost, last.initial_cost);
    }
  }
}

// --ego-truth replaces the odometry (noisy, one frame missing) by the true poses: the ego that
// comes out is the truth, re-based on frame 0, in every frame, and the objects are estimated on it.
TEST(BackendNode, OfflineReplayOnTheTrueEgo) {
  const std::string dir = scratchDir();
  SimScene scene = parkedAndMovingScene(7, 9);
  scene.ego = constantTwist(planarPose(5, -2, 0.3), 10.0, 0.05);  // frame 0 is not the identity
  const auto inputs = scene.generate(25);
  writeLog(dir + "/in.lcmlog", inputs);
  std::vector<Pose> truth;
  for (int t = 0; t < 25; ++t) truth.push_back(scene.egoTruth(t));
  kitti::writePoses(dir + "/truth.txt", truth);
  const std::string out_path = dir + "/out.lcmlog";
  ChildProcess p({bin("dlslot-backend"), "--config", config(), "--offline", dir + "/in.lcmlog", "--out", out_path,
                  "--mode", "two-stage", "--ego-truth", dir + "/truth.txt"},
                 dir + "/backend.txt");
  ASSERT_EQ(p.wait(120), 0) << p.output();
  const auto states = decodeAll<slot_state_t>(readLog(out_path)["SLOT_STATE"]);
  ASSERT_EQ(states.size(), 25u);
  for (size_t t = 0; t < states.size(); ++t) {
    const Pose expected = truth.front().inverse() * truth[t];
    const Pose got = fromMsg(states[t].ego_pose);
    EXPECT_LT((got.translation() - expected.translation()).norm(), 1e-6) << "frame " << t;
    EXPECT_LT(Eigen::AngleAxisd(got.linear().transpose() * expected.linear()).angle(), 1e-8) << "frame " << t;
    EXPECT_FALSE(states[t].odometry_missing) << "frame " << t;  // frame 7's odometry is the truth too
  }
  const slot_state_t& last = states.back();
  ASSERT_EQ(last.num_tracks, 2);
  for (const track_t& tr : last.tracks)
    if (tr.id == 2) {
      EXPECT_NEAR(std::hypot(tr.velocity[0], tr.velocity[1]), 12.0, 0.5);
    }

  // Fewer poses than frames: an error naming the file and the frame.
  truth.resize(20);
  kitti::writePoses(dir + "/short.txt", truth);
  ChildProcess short_truth({bin("dlslot-backend"), "--config", config(), "--offline", dir + "/in.lcmlog",
                            "--ego-truth", dir + "/short.txt"},
                           dir + "/short-out.txt");
  EXPECT_NE(short_truth.wait(120), 0);
  EXPECT_NE(short_truth.output().find("short.txt: no pose for frame 20"), std::string::npos) << short_truth.output();
  // Without --offline it is refused.
  ChildProcess live({bin("dlslot-backend"), "--config", config(), "--ego-truth", dir + "/truth.txt"}, dir + "/live.txt");
  EXPECT_EQ(live.wait(30), 2);
}

TEST(BackendNode, CommandLineErrors) {
  const std::string dir = scratchDir();
  ChildProcess bad_mode({bin("dlslot-backend"), "--config", config(), "--mode", "joint", "--check-config"}, dir + "/a.txt");
  EXPECT_EQ(bad_mode.wait(30), 2);
  EXPECT_NE(bad_mode.output().find("joint"), std::string::npos);
  ChildProcess out_only({bin("dlslot-backend"), "--config", config(), "--out", dir + "/x.lcmlog"}, dir + "/b.txt");
  EXPECT_EQ(out_only.wait(30), 2);
  ChildProcess missing({bin("dlslot-backend"), "--config", config(), "--offline", dir + "/none.lcmlog"}, dir + "/c.txt");
  EXPECT_NE(missing.wait(30), 0);
  EXPECT_NE(missing.output().find("none.lcmlog"), std::string::npos);
  ChildProcess ok({bin("dlslot-backend"), "--config", config(), "--check-config"}, dir + "/d.txt");
  EXPECT_EQ(ok.wait(30), 0) << ok.output();
}
