// The pipeline across two hosts. Two network namespaces joined by a veth pair
// stand for two machines on one link, with multicast routed over it: the player and the odometry
// run on "the vehicle" (this test's namespace), the tracker, backend, renderer and a logger on
// "the other machine", every process with the README's multi-host LCM URL (section "Across
// machines", TTL 1). Lockstep on SLOT_STATE, which crosses the link back to the player. The
// result must equal a single-host run of the same sequence: same frames, same odometry poses,
// same SLOT_STATE (ego poses, tracks), byte for byte but for wall-clock timings.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <thread>

#include "dlslot/odometry_t.hpp"
#include "dlslot/process_status_t.hpp"
#include "dlslot/slot_state_t.hpp"
#include "dlslot/message_auth.hpp"
#include "process_harness.hpp"

using namespace dlslot;
using namespace dlslot::test;
namespace fs = std::filesystem;

namespace {

constexpr int kFrames = 25;

// The multi-host URL the README gives, so the test and the documentation cannot drift apart.
std::string readmeMultiHostUrl() {
  std::ifstream in(sourceDir() + "/README.md");
  std::stringstream text;
  text << in.rdbuf();
  std::smatch m;
  const std::string s = text.str();
  const auto section = s.find("## Across machines");
  if (section == std::string::npos) return "";
  const std::string rest = s.substr(section);
  if (!std::regex_search(rest, m, std::regex(R"(`(udpm://[0-9.]+:[0-9]+\?ttl=1[^`]*)`)"))) return "";
  return m[1];
}

int sh(const std::string& cmd) {
  const int rc = std::system(cmd.c_str());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

template <class Msg>
std::vector<Msg> withoutTimings(std::vector<Msg> msgs) {
  for (Msg& m : msgs) {
    m.timings.clear();
    m.num_timings = 0;
  }
  return msgs;
}

template <class Msg>
std::vector<uint8_t> encoded(Msg m) {
  std::vector<uint8_t> buf(m.getEncodedSize());
  m.encode(buf.data(), 0, buf.size());
  return buf;
}

// Waits until every name has published PROCESS_STATUS on `url`.
bool waitForStatus(const std::string& url, std::set<std::string> names, double timeout_s) {
  lcm::LCM lcm(url);
  if (!lcm.good()) return false;
  struct Seen {
    std::set<std::string>* names;
  } seen{&names};
  lcm.subscribeFunction<Seen*>(
      "PROCESS_STATUS",
      [](const lcm::ReceiveBuffer* rbuf, const std::string&, Seen* s) {
        process_status_t m;
        const auto* d = static_cast<const uint8_t*>(rbuf->data);
        size_t n = rbuf->data_size;
        if (dlslot::isEnvelope(d, n)) {  // (not verified here: this listener only waits for names)
          d += dlslot::kEnvelopeHeader;
          n -= dlslot::kEnvelopeHeader + dlslot::kEnvelopeTag;
        }
        if (m.decode(d, 0, static_cast<int>(n)) > 0) s->names->erase(m.name);
      },
      &seen);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (!names.empty() && std::chrono::steady_clock::now() < deadline) lcm.handleTimeout(100);
  return names.empty();
}

}  // namespace

TEST(PipelineTwoHostsProcess, SplitAcrossTwoNamespacesEqualsOneHost) {
  ASSERT_TRUE(insidePrivateNetwork());
  // Links and routes are made only in a namespace of our own, never on the host network.
  const char* where = std::getenv("DLSLOT_NETNS");
  if (!where || std::string(where) != "private") GTEST_SKIP() << "no private network namespace here";
  const std::string url = readmeMultiHostUrl();
  ASSERT_FALSE(url.empty()) << "README.md's \"Across machines\" gives no udpm://...?ttl=1 URL in backticks";
  const std::string out = scratchDir();
  const std::string data = out + "/data";
  ChildProcess sim({bin("dlslot-sim"), "--scenario", "intersection", "--frames", std::to_string(kFrames), "--seed",
                    "4", "--out", data},
                   out + "/sim.log");
  ASSERT_EQ(sim.wait(300), 0) << sim.output();

  // 1. One host: the whole pipeline in this namespace (multicast on its loopback).
  ChildProcess single({bin("dlslot-run"), "--config", config(), "--kitti", data, "--detections",
                       data + "/detections/sim", "--out", out + "/single", "--quiet", "--no-eval"},
                      out + "/single.log");
  ASSERT_EQ(single.wait(600), 0) << single.output();

  // 2. The second host: a namespace of its own, held open by a sleeping process, joined to this
  // one by a veth pair; multicast routed over the link on both sides.
  ChildProcess holder({"/usr/bin/unshare", "-n", "/bin/sleep", "900"}, out + "/holder.log");
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  ASSERT_TRUE(holder.running()) << "cannot make a second network namespace: " << holder.output();
  const std::string other = "/usr/bin/nsenter -t " + std::to_string(holder.pid()) + " -n ";
  ASSERT_EQ(sh("ip link add dlslot-a type veth peer name dlslot-b netns " + std::to_string(holder.pid())), 0);
  ASSERT_EQ(sh("ip addr add 10.76.0.1/24 dev dlslot-a && ip link set dlslot-a multicast on up && "
               "ip route replace 224.0.0.0/4 dev dlslot-a"),
            0);
  ASSERT_EQ(sh(other + "sh -c 'ip link set lo up && ip addr add 10.76.0.2/24 dev dlslot-b && "
                       "ip link set dlslot-b multicast on up && ip route add 224.0.0.0/4 dev dlslot-b'"),
            0);

  // One key file on both hosts (docs/security.md): every message authenticated across the link.
  const std::string key = out + "/shared.key";
  ChildProcess make({bin("dlslot-run"), "--make-key", key}, out + "/make-key.log");
  ASSERT_EQ(make.wait(30), 0) << make.output();
  const std::vector<std::string> lcm = {"--config", config(), "--lcm-url", url, "--key", key};
  auto on = [&](bool remote, const std::string& exe, std::vector<std::string> extra) {
    std::vector<std::string> a;
    if (remote) a = {"/usr/bin/nsenter", "-t", std::to_string(holder.pid()), "-n"};
    a.push_back(bin(exe));
    a.insert(a.end(), lcm.begin(), lcm.end());
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  };
  const std::string split = out + "/split";
  fs::create_directories(split + "/logs");
  ChildProcess logger({"/usr/bin/nsenter", "-t", std::to_string(holder.pid()), "-n", "/usr/bin/lcm-logger",
                       "--quiet", "--force", "--lcm-url=" + url, split + "/run.lcmlog"},
                      split + "/logs/lcm-logger.log");
  ChildProcess renderer(on(true, "dlslot-renderer", {"--out", split + "/bev"}), split + "/logs/renderer.log");
  ChildProcess backend(on(true, "dlslot-backend", {"--mode", "slot"}), split + "/logs/backend.log");
  ChildProcess tracker(on(true, "dlslot-tracker", {}), split + "/logs/tracker.log");
  ChildProcess odometry(on(false, "dlslot-odometry", {"--mode", "aloam-filtered"}), split + "/logs/odometry.log");
  // Heard from this side: the other host's processes are reachable over the link.
  ASSERT_TRUE(waitForStatus(url, {"renderer", "backend", "tracker", "odometry"}, 30))
      << "not every process was heard across the link\n"
      << tracker.output() << backend.output() << odometry.output();
  ChildProcess player(on(false, "dlslot-player",
                         {"--kitti", data, "--sequence", "0000", "--detections", data + "/detections/sim", "--quiet",
                          "--delay", "0.2", "--lockstep", "SLOT_STATE"}),
                      split + "/logs/player.log");
  ASSERT_EQ(player.wait(300), 0) << player.output();
  for (ChildProcess* p : {&odometry, &tracker, &backend, &renderer}) EXPECT_EQ(p->stop(), 0) << p->output();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  logger.stop();

  // 3. The same frames, odometry and SLOT_STATE on both.
  // Every process on both hosts verified what it received: nothing was refused.
  for (ChildProcess* p : {&odometry, &tracker, &backend, &renderer, &player}) {
    EXPECT_NE(p->output().find("messages authenticated with the run key"), std::string::npos) << p->output();
    EXPECT_EQ(p->output().find("refused a message"), std::string::npos) << p->output();
  }
  fs::copy_file(key, split + "/run.key");  // the log verifies with the run's key
  auto one = readLog(out + "/single/run.lcmlog"), two = readLog(split + "/run.lcmlog");
  const auto odo1 = withoutTimings(decodeAll<odometry_t>(one["ODOMETRY"]));
  const auto odo2 = withoutTimings(decodeAll<odometry_t>(two["ODOMETRY"]));
  const auto slot1 = withoutTimings(decodeAll<slot_state_t>(one["SLOT_STATE"]));
  const auto slot2 = withoutTimings(decodeAll<slot_state_t>(two["SLOT_STATE"]));
  ASSERT_EQ(slot1.size(), static_cast<size_t>(kFrames));
  ASSERT_EQ(slot2.size(), slot1.size());
  ASSERT_EQ(odo2.size(), odo1.size());
  size_t tracks = 0;
  for (size_t i = 0; i < slot1.size(); ++i) {
    EXPECT_EQ(slot2[i].frame, slot1[i].frame);
    EXPECT_EQ(encoded(slot2[i]), encoded(slot1[i])) << "SLOT_STATE of frame " << slot1[i].frame << " differs";
    tracks += slot1[i].tracks.size();
  }
  for (size_t i = 0; i < odo1.size(); ++i)
    EXPECT_EQ(encoded(odo2[i]), encoded(odo1[i])) << "ODOMETRY of frame " << odo1[i].frame << " differs";
  // Over the link, not around it: the scans the other host logged came from this namespace.
  EXPECT_EQ(two["LIDAR_SCAN"].size(), static_cast<size_t>(kFrames));
  EXPECT_GT(tracks, 0u);
  std::cout << "[ two hosts ] " << slot2.size() << " SLOT_STATE frames (" << tracks << " track states) and "
            << odo2.size() << " ODOMETRY poses over a veth link with " << url << ": identical to one host\n";
  sh("ip link del dlslot-a 2>/dev/null");
}
