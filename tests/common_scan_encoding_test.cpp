// encodeScan writes the bytes lcm-gen's point_cloud_t::encode writes.
#include <gtest/gtest.h>

#include <limits>
#include <random>

#include "dlslot/convert.hpp"
#include "dlslot/point_cloud_t.hpp"
#include "dlslot/scan_encoding.hpp"

using namespace dlslot;

namespace {

std::vector<uint8_t> lcmGenBytes(const PointCloud& scan, int64_t utime, int32_t frame, const std::string& seq) {
  point_cloud_t msg;
  msg.utime = utime;
  msg.frame = frame;
  msg.sequence = seq;
  toMsg(scan, msg);
  std::vector<uint8_t> out(msg.getEncodedSize());
  EXPECT_EQ(msg.encode(out.data(), 0, static_cast<int>(out.size())), static_cast<int>(out.size()));
  return out;
}

TEST(ScanEncoding, SameBytesAsLcmGen) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-80, 80);
  std::vector<uint8_t> buf;
  for (int n : {0, 1, 7, 1000, 123457}) {
    PointCloud scan(4, n);
    for (Eigen::Index i = 0; i < scan.cols(); ++i) scan.col(i) << u(rng), u(rng), u(rng) / 20, std::abs(u(rng)) / 80;
    if (n > 2) {  // the bit patterns a byte swap could get wrong
      scan(0, 0) = -0.0f;
      scan(1, 1) = std::numeric_limits<float>::denorm_min();
      scan(2, 2) = std::numeric_limits<float>::max();
    }
    for (const std::string seq : {"0000", "", "a-long-sequence-name-0042"}) {
      encodeScan(scan, 1234567890123LL + n, n, seq, buf);
      EXPECT_EQ(buf, lcmGenBytes(scan, 1234567890123LL + n, n, seq)) << n << " points, sequence '" << seq << "'";
    }
  }
}

TEST(ScanEncoding, DecodesToTheScan) {
  PointCloud scan(4, 3);
  scan << 1, 2, 3, -4, 5, 6, 7, 8, 9, 0.1f, 0.2f, 0.3f;
  std::vector<uint8_t> buf;
  encodeScan(scan, -5, 42, "0007", buf);
  point_cloud_t msg;
  ASSERT_EQ(msg.decode(buf.data(), 0, static_cast<int>(buf.size())), static_cast<int>(buf.size()));
  EXPECT_EQ(msg.utime, -5);
  EXPECT_EQ(msg.frame, 42);
  EXPECT_EQ(msg.sequence, "0007");
  EXPECT_EQ(fromMsg(msg), scan);
}

// A buffer reused for a smaller scan holds exactly the smaller scan's bytes.
TEST(ScanEncoding, ReusedBufferShrinks) {
  std::vector<uint8_t> buf;
  encodeScan(PointCloud::Ones(4, 500), 1, 1, "0000", buf);
  const PointCloud small = PointCloud::Constant(4, 10, 2.5f);
  encodeScan(small, 2, 2, "0000", buf);
  EXPECT_EQ(buf, lcmGenBytes(small, 2, 2, "0000"));
}

}  // namespace
