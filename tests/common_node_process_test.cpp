// The node layer's large-message filter, for real over LCM multicast (private network namespace,
// tests/CMakeLists.txt): a node that takes no scans never receives a message of
// kLargeMessageBytes or more, receives every smaller one, and the kernel counts no drop for what
// it trims; a node that subscribes to the scan channel receives the large ones. And a node that
// asks for a deeper receive buffer (the mapper) holds a backlog larger than the usual buffer.
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include <cstdio>
#include <vector>

#include "dlslot/frame_accounting.hpp"
#include "dlslot/large_message_filter.hpp"
#include "dlslot/node.hpp"
#include "dlslot/receive_buffer.hpp"

using namespace dlslot;

namespace {

struct Counts {
  int small = 0, medium = 0, large = 0;
  size_t large_bytes = 0;
};

void countOn(Node& node, const std::string& channel, Counts* c) {
  node.subscribeRaw(channel, [c](const lcm::ReceiveBuffer& rbuf) {
    if (rbuf.data_size >= kLargeMessageBytes) {
      ++c->large;
      c->large_bytes = rbuf.data_size;
    } else if (rbuf.data_size > 1400) {
      ++c->medium;  // fragmented by LCM, but under the threshold
    } else {
      ++c->small;
    }
  });
}

// Publishes, on `channel`, a small, a medium (300 kB, fragmented) and a large (2 MB) message,
// `times` times each; then lets `node` handle what arrives.
void publishAll(lcm::LCM& pub, const std::string& channel, int times, Node& node) {
  const std::vector<uint8_t> small(200, 1), medium(300000, 2), large(2000000, 3);
  for (int i = 0; i < times; ++i) {
    pub.publish(channel, small.data(), small.size());
    pub.publish(channel, medium.data(), medium.size());
    pub.publish(channel, large.data(), large.size());
  }
  node.spinUntil([] { return false; }, 0.5);
}

TEST(LargeMessageFilter, NodeWithoutScansGetsEverythingButLargeMessages) {
  lcm::LCM pub;
  ASSERT_TRUE(pub.good());
  Node node("no-scans", "");
  Counts got;
  countOn(node, "SLOT_STATE", &got);
  publishAll(pub, "SLOT_STATE", 3, node);
  EXPECT_EQ(got.small, 3);
  EXPECT_EQ(got.medium, 3);
  EXPECT_EQ(got.large, 0);
  // Trimmed, not dropped: the kernel's drop count (the frame accounting's "receive buffer full")
  // stays at zero.
  // The node's is the process's only receive socket on the port (`pub` only sends).
  const char* url = std::getenv("LCM_DEFAULT_URL");
  ASSERT_NE(url, nullptr) << "run inside scripts/netns-run";
  const std::vector<int> sockets = udpSocketsOnPort(lcmPort(url));
  ASSERT_EQ(sockets.size(), 1u);
  EXPECT_EQ(udpDrops(sockets.front()), 0);
}

TEST(LargeMessageFilter, NodeWithScansGetsLargeMessages) {
  lcm::LCM pub;
  ASSERT_TRUE(pub.good());
  Node node("scans", "");
  Counts scans, other;
  countOn(node, Channels().scan, &scans);
  countOn(node, "OTHER", &other);
  publishAll(pub, Channels().scan, 2, node);
  publishAll(pub, "OTHER", 2, node);
  EXPECT_EQ(scans.large, 2);
  EXPECT_EQ(scans.large_bytes, 2000000u);
  EXPECT_EQ(scans.medium, 2);
  EXPECT_EQ(scans.small, 2);
  // Once a node takes scans, a large message on another channel reaches it too.
  EXPECT_EQ(other.large, 2);
}

// Another socket on the port in the same process (as a launched child holds its launcher's, or
// a launcher its test's): the node filters its own socket only, the other still gets everything.
TEST(LargeMessageFilter, OnlyTheNodesOwnSocketIsFiltered) {
  lcm::LCM pub, other;
  ASSERT_TRUE(pub.good() && other.good());
  int other_large = 0;
  other.subscribeFunction<int*>(
      "SLOT_STATE", [](const lcm::ReceiveBuffer* rbuf, const std::string&, int* n) { *n += rbuf->data_size >= kLargeMessageBytes; },
      &other_large);
  other.getFileno();  // its receive socket exists before the node's
  Node node("no-scans", "");
  Counts got;
  countOn(node, "SLOT_STATE", &got);
  publishAll(pub, "SLOT_STATE", 2, node);
  while (other.handleTimeout(50) > 0) {
  }
  EXPECT_EQ(got.large, 0);
  EXPECT_EQ(got.medium, 2);
  EXPECT_EQ(other_large, 2);
}

TEST(LargeMessageFilter, LargeMessageOffTheScanChannelIsAnError) {
  Node node("publisher", "");
  const std::vector<uint8_t> large(kLargeMessageBytes, 0), below(kLargeMessageBytes - 1, 0);
  node.publishEncoded(Channels().scan, large.data(), large.size());
  node.publishEncoded("SLOT_STATE", below.data(), below.size());
  EXPECT_EQ(node.status().toMessage().errors, 0);
  node.publishEncoded("SLOT_STATE", large.data(), large.size());
  EXPECT_EQ(node.status().toMessage().errors, 1);
  EXPECT_NE(node.status().toMessage().last_warning.find("SLOT_STATE"), std::string::npos);
}

}  // namespace

// A process that lags the pipeline by design (the mapper) holds four times the URL's buffer: 15
// scans of 2 MB published while nobody reads (30 MB, more than the 16 MB every node holds) all
// reach it. A node with the URL's buffer usually loses some to the kernel, but not always: LCM's
// own receive thread may drain its socket during the burst, so that side is printed, not asserted.
TEST(ReceiveBuffer, ADeepenedBufferHoldsABacklogTwiceTheUsualSize) {
  lcm::LCM pub;
  ASSERT_TRUE(pub.good());
  Node usual("usual", ""), deep("deep", "");
  deep.setReceiveBuffer(4);
  const int64_t usual_bytes = statusCounter(usual.status().toMessage(), "recv_buffer_bytes");
  const int64_t deep_bytes = statusCounter(deep.status().toMessage(), "recv_buffer_bytes");
  ASSERT_GT(usual_bytes, 0) << "no recv_buf_size in $LCM_DEFAULT_URL";
  EXPECT_GE(deep_bytes, 4 * usual_bytes);
  Counts u, d;
  countOn(usual, Channels().scan, &u);
  countOn(deep, Channels().scan, &d);
  const std::vector<uint8_t> scan(2000000, 7);
  for (int i = 0; i < 15; ++i) pub.publish(Channels().scan, scan.data(), static_cast<unsigned>(scan.size()));
  usual.spinUntil([] { return false; }, 0.5);
  deep.spinUntil([] { return false; }, 0.5);
  EXPECT_EQ(d.large, 15);
  std::printf("15 scans of 2 MB while nobody read: %d reached the usual buffer, %d the deepened one\n", u.large, d.large);
}
