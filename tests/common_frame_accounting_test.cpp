// Frame accounting (frame_accounting.hpp) on hand-made PROCESS_STATUS messages, and the receive
// buffer helpers on a real socket.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include "dlslot/frame_accounting.hpp"
#include "dlslot/receive_buffer.hpp"

using namespace dlslot;

namespace {

process_status_t status(const std::string& name, int64_t handled, std::map<std::string, int64_t> counters) {
  process_status_t s{};
  s.name = name;
  s.frames_handled = handled;
  for (const auto& [k, v] : counters) {
    s.counter_names.push_back(k);
    s.counter_values.push_back(v);
  }
  s.num_counters = static_cast<int32_t>(s.counter_names.size());
  return s;
}

}  // namespace

TEST(FrameAccounting, CompleteRunHasNoLoss) {
  std::map<std::string, process_status_t> last = {
      {"player", status("player", 100, {})},
      {"odometry", status("odometry", 100, {{"frames_received", 100}})},
      {"tracker", status("tracker", 100, {{"frames_received", 100}})},
      {"backend", status("backend", 100, {{"frames_received", 100}})},
      {"renderer", status("renderer", 90, {{"frames_received", 100}, {"frames_skipped", 10}})}};
  const FrameAccounting a = accountFrames(last, 5, {"odometry", "tracker", "backend", "renderer"});
  EXPECT_EQ(a.played, 100);  // the player's own count wins over the caller's
  EXPECT_EQ(a.lost(), 0);
  EXPECT_FALSE(a.hasLoss());
  EXPECT_EQ(a.processes[3].skipped, 10);
  EXPECT_NE(a.verdict().find("0 frames lost"), std::string::npos);
  EXPECT_NE(a.verdict().find("renderer skipped 10"), std::string::npos);
}

TEST(FrameAccounting, LossesAreCountedWhereTheyHappened) {
  std::map<std::string, process_status_t> last = {
      {"player", status("player", 1000, {})},
      {"odometry", status("odometry", 922, {{"frames_received", 1000}, {"udp_drops", 2400}})},
      {"tracker", status("tracker", 1000, {{"odometry_missing", 78}})},
      {"backend", status("backend", 1000, {{"odometry_missing", 200}, {"associations_missing", 3}})}};
  const FrameAccounting a = accountFrames(last, 1000, {"odometry", "tracker", "backend", "renderer"});
  EXPECT_EQ(a.processes[0].lost, 78);
  EXPECT_EQ(a.processes[1].lost, 0);
  EXPECT_FALSE(a.processes[3].reported);
  EXPECT_EQ(a.processes[3].lost, 1000);  // a process that never reported handled nothing
  EXPECT_EQ(a.without_odometry, 200);
  EXPECT_EQ(a.without_associations, 3);
  EXPECT_EQ(a.kernel_drops, 2400);
  EXPECT_TRUE(a.hasLoss());
  const std::string v = a.verdict();
  EXPECT_EQ(v.rfind("LOSSES: 1078 frames lost of 1000 played (odometry 78, renderer 1000)", 0), 0u) << v;
  EXPECT_NE(v.find("200 solved without odometry"), std::string::npos);
}

TEST(FrameAccounting, RssStartMiddleThreeQuartersEnd) {
  EXPECT_FALSE(summarizeRss({}).has_value());
  const auto r = summarizeRss({{0.0, 1024}, {4.0, 2048}, {5.2, 3072}, {7.0, 5120}, {10.0, 4096}});
  ASSERT_TRUE(r);
  EXPECT_DOUBLE_EQ(r->start_mb, 1.0);
  EXPECT_DOUBLE_EQ(r->middle_mb, 3.0);          // 5.2 s is nearest the midpoint 5 s
  EXPECT_DOUBLE_EQ(r->three_quarters_mb, 5.0);  // 7 s is nearest 7.5 s
  EXPECT_DOUBLE_EQ(r->end_mb, 4.0);
  EXPECT_GT(residentKb(), 0);
}

TEST(ReceiveBuffer, UrlParameters) {
  EXPECT_EQ(requestedReceiveBuffer("udpm://239.255.76.67:7667?ttl=0&recv_buf_size=8388608"), 8388608);
  EXPECT_EQ(requestedReceiveBuffer("udpm://239.255.76.67:7667?recv_buf_size=0x100000"), 1048576);
  EXPECT_EQ(requestedReceiveBuffer("udpm://239.255.76.67:7667?ttl=0"), 0);
  EXPECT_EQ(requestedReceiveBuffer("udpm://239.255.76.67:7667?recv_buf_size=8M"), 0);  // not a number
  EXPECT_EQ(requestedReceiveBuffer("file:///tmp/x.log?recv_buf_size=100"), 0);
  EXPECT_EQ(lcmPort("udpm://239.255.76.67:7701?ttl=1"), 7701);
  EXPECT_EQ(lcmPort("udpm://239.255.76.67"), 7667);
  EXPECT_EQ(lcmPort("memq://"), 0);
}

TEST(ReceiveBuffer, EnlargesTheSocketOnThePort) {
  const int fd = socket(AF_INET, SOCK_DGRAM, 0);
  ASSERT_GE(fd, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t len = sizeof addr;
  ASSERT_EQ(bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  ASSERT_EQ(getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len), 0);
  const int port = ntohs(addr.sin_port);
  const ReceiveBuffer r = enlargeLcmReceiveBuffer(port, 1 << 20);
  EXPECT_EQ(r.fd, fd);
  int now = 0;
  len = sizeof now;
  getsockopt(fd, SOL_SOCKET, SO_RCVBUF, &now, &len);
  EXPECT_EQ(r.granted, now);
  // The kernel doubles what it grants; forced, it grants exactly that, else at most 2 x rmem_max.
  if (r.forced) {
    EXPECT_EQ(r.granted, 2 << 20);
  }
  EXPECT_GT(r.granted, 0);
  EXPECT_EQ(udpDrops(fd), 0);
  EXPECT_GE(udpReceiveBufferErrors(), 0);
  EXPECT_EQ(enlargeLcmReceiveBuffer(port == 65535 ? 65534 : port + 1, 1 << 20).fd, -1);
  close(fd);
}
