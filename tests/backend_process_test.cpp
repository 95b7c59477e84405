// dlslot-backend as a live process (inside a private network namespace): ODOMETRY and
// ASSOCIATIONS in, SLOT_STATE and PROCESS_STATUS out; a frame missing either input is handled
// after the join timeout and reported; garbage on an input channel is counted, not fatal.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <fstream>

#include "backend_scene.hpp"
#include "backend_test_messages.hpp"
#include "dlslot/process_status_t.hpp"
#include "dlslot/slot_state_t.hpp"
#include "process_harness.hpp"

using namespace dlslot;
using namespace dlslot::backend;
using namespace dlslot::backend::test;
using dlslot::test::bin;
using dlslot::test::ChildProcess;
using dlslot::test::insidePrivateNetwork;
using dlslot::test::scratchDir;

TEST(BackendProcess, LiveFramesWithMissingInputs) {
  ASSERT_TRUE(insidePrivateNetwork()) << "run through scripts/netns-run (ctest does)";
  const std::string dir = scratchDir();
  // The shipped config with a short join timeout.
  YAML::Node cfg = YAML::LoadFile(dlslot::test::config());
  cfg["backend"]["join_timeout_s"] = 0.3;
  const std::string cfg_path = dir + "/dlslot.yaml";
  std::ofstream(cfg_path) << cfg;

  const SimScene scene = parkedAndMovingScene(5, 8);
  const auto inputs = scene.generate(14);

  lcm::LCM lcm;
  ASSERT_TRUE(lcm.good());
  std::vector<slot_state_t> states;
  std::vector<process_status_t> statuses;
  struct Ctx {
    std::vector<slot_state_t>* states;
    std::vector<process_status_t>* statuses;
  } ctx{&states, &statuses};
  lcm.subscribeFunction<Ctx*>(
      "SLOT_STATE",
      [](const lcm::ReceiveBuffer* rbuf, const std::string&, Ctx* c) {
        slot_state_t s;
        if (s.decode(rbuf->data, 0, rbuf->data_size) >= 0) c->states->push_back(s);
      },
      &ctx);
  lcm.subscribeFunction<Ctx*>(
      "PROCESS_STATUS",
      [](const lcm::ReceiveBuffer* rbuf, const std::string&, Ctx* c) {
        process_status_t s;
        if (s.decode(rbuf->data, 0, rbuf->data_size) >= 0 && s.name == "backend") c->statuses->push_back(s);
      },
      &ctx);

  ChildProcess backend({bin("dlslot-backend"), "--config", cfg_path}, dir + "/backend.txt");
  auto spin = [&](const std::function<bool()>& done, double timeout_s) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while (!done() && std::chrono::steady_clock::now() < end) lcm.handleTimeout(20);
    return done();
  };
  ASSERT_TRUE(spin([&] { return !statuses.empty(); }, 10.0)) << backend.output();  // it is up

  const uint8_t garbage[] = {1, 2, 3};
  lcm.publish("ODOMETRY", garbage, sizeof(garbage));
  for (const BackendInput& in : inputs) {
    if (in.odometry) {
      const odometry_t o = odometryMsg(in);
      lcm.publish("ODOMETRY", &o);
    }
    if (!in.associations_missing) {
      const associations_t bad = malformedAssociationsMsg(in);  // refused whole, then the real one
      lcm.publish("ASSOCIATIONS", &bad);
      const associations_t a = associationsMsg(in);
      lcm.publish("ASSOCIATIONS", &a);
    }
    // Lockstep, as the player runs it: the next frame only after this frame's SLOT_STATE.
    const size_t want = static_cast<size_t>(in.frame) + 1;
    ASSERT_TRUE(spin([&] { return states.size() >= want; }, 5.0)) << "frame " << in.frame << "\n" << backend.output();
  }
  const size_t before = statuses.size();
  ASSERT_TRUE(spin([&] { return statuses.size() > before + 1; }, 5.0));
  EXPECT_EQ(backend.stop(), 0) << backend.output();

  ASSERT_EQ(states.size(), inputs.size());
  for (size_t t = 0; t < states.size(); ++t) {
    EXPECT_EQ(states[t].frame, static_cast<int>(t));
    EXPECT_EQ(states[t].odometry_missing, t == 5) << t;
    EXPECT_EQ(states[t].associations_missing, t == 8) << t;
  }
  EXPECT_EQ(states.back().num_tracks, 2);
  EXPECT_LT((fromMsg(states.back().ego_pose).translation() - scene.egoTruth(13).translation()).norm(), 0.5);

  const process_status_t& st = statuses.back();
  EXPECT_EQ(st.frames_handled, 14);
  EXPECT_EQ(st.last_frame, 13);
  EXPECT_EQ(st.timeouts, 2);
  EXPECT_EQ(st.decode_errors, 1);
  EXPECT_GE(st.errors, 13);  // one message with a malformed box per frame with ASSOCIATIONS
  std::map<std::string, int64_t> counters;
  for (int i = 0; i < st.num_counters; ++i) counters[st.counter_names[i]] = st.counter_values[i];
  EXPECT_EQ(counters["refused.ASSOCIATIONS.non_finite"], 13);
  EXPECT_EQ(counters["odometry_missing"], 1);
  EXPECT_EQ(counters["associations_missing"], 1);
  EXPECT_GT(counters["last_iterations"], 0);
  EXPECT_GT(counters["last_solve_us"], 0);
}
