// The live bridge's binary scan: sensor_msgs/PointCloud2 in ROS 1 serialization
// (tools/foxglove/ros1_point_cloud.hpp), checked byte for byte against a message written out by
// hand from the ROS 1 wire format, and read back by a reader written here from that format.
#include <gtest/gtest.h>

#include <cstring>
#include <limits>
#include <random>

#include "foxglove_convert.hpp"
#include "ros1_point_cloud.hpp"

using namespace dlslot;
using namespace dlslot::foxglove;

namespace {

point_cloud_t cloud(int64_t utime, int frame, std::vector<std::array<float, 4>> points) {
  point_cloud_t m{};
  m.utime = utime;
  m.frame = frame;
  m.sequence = "0000";
  m.num_points = static_cast<int>(points.size());
  for (const auto& p : points) {
    m.x.push_back(p[0]);
    m.y.push_back(p[1]);
    m.z.push_back(p[2]);
    m.intensity.push_back(p[3]);
  }
  return m;
}

// A ROS 1 reader for the test: little-endian, sequential, uint32-prefixed strings and arrays.
struct Reader {
  const std::string& b;
  size_t at = 0;
  template <class T>
  T get() {
    T v;
    if (at + sizeof v > b.size()) throw std::out_of_range("read past the end at " + std::to_string(at));
    std::memcpy(&v, b.data() + at, sizeof v);
    at += sizeof v;
    return v;
  }
  std::string str() {
    const uint32_t n = get<uint32_t>();
    if (at + n > b.size()) throw std::out_of_range("string past the end");
    std::string s = b.substr(at, n);
    at += n;
    return s;
  }
};

TEST(Ros1PointCloud, TwoPointsAreTheBytesOfTheRos1WireFormat) {
  const point_cloud_t m = cloud(1'500'000, 7, {{1.0f, -2.0f, 0.5f, 0.25f}, {3.0f, 0.0f, 4.0f, 1.0f}});
  std::string out = "old contents are replaced";
  ros1::writePointCloud2(m, "lidar", out);
  const std::vector<uint8_t> want = {
      7, 0, 0, 0,                             // header.seq = frame
      1, 0, 0, 0, 0x00, 0x65, 0xCD, 0x1D,     // header.stamp: 1 s, 500000000 ns
      5, 0, 0, 0, 'l', 'i', 'd', 'a', 'r',    // header.frame_id
      1, 0, 0, 0,                             // height
      2, 0, 0, 0,                             // width
      4, 0, 0, 0,                             // fields[4]
      1, 0, 0, 0, 'x', 0, 0, 0, 0, 7, 1, 0, 0, 0,    // name, offset, datatype FLOAT32, count
      1, 0, 0, 0, 'y', 4, 0, 0, 0, 7, 1, 0, 0, 0,
      1, 0, 0, 0, 'z', 8, 0, 0, 0, 7, 1, 0, 0, 0,
      9, 0, 0, 0, 'i', 'n', 't', 'e', 'n', 's', 'i', 't', 'y', 12, 0, 0, 0, 7, 1, 0, 0, 0,
      0,                                      // is_bigendian
      16, 0, 0, 0,                            // point_step
      32, 0, 0, 0,                            // row_step
      32, 0, 0, 0,                            // data[32]
      0x00, 0x00, 0x80, 0x3F, 0x00, 0x00, 0x00, 0xC0, 0x00, 0x00, 0x00, 0x3F, 0x00, 0x00, 0x80, 0x3E,  // 1 -2 0.5 0.25
      0x00, 0x00, 0x40, 0x40, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x80, 0x40, 0x00, 0x00, 0x80, 0x3F,  // 3 0 4 1
      1,                                      // is_dense
  };
  EXPECT_EQ(std::vector<uint8_t>(out.begin(), out.end()), want);
}

TEST(Ros1PointCloud, ReadsBackAsTheScanItWasWrittenFrom) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-80, 80);
  std::string out;
  for (int n : {0, 1, 1000, 123457}) {  // a buffer reused for smaller scans holds exactly the new one
    std::vector<std::array<float, 4>> pts(n);
    for (auto& p : pts) p = {u(rng), u(rng), u(rng) / 20, std::abs(u(rng)) / 80};
    const int64_t utime = 1'234'567'890'123'456LL + n;
    const point_cloud_t m = cloud(utime, n, pts);
    ros1::writePointCloud2(m, "lidar", out);
    Reader r{out};
    EXPECT_EQ(r.get<uint32_t>(), static_cast<uint32_t>(n));
    EXPECT_EQ(r.get<uint32_t>(), utime / 1000000);
    EXPECT_EQ(r.get<uint32_t>(), utime % 1000000 * 1000);
    EXPECT_EQ(r.str(), "lidar");
    EXPECT_EQ(r.get<uint32_t>(), 1u);
    EXPECT_EQ(r.get<uint32_t>(), static_cast<uint32_t>(n));
    ASSERT_EQ(r.get<uint32_t>(), 4u);
    uint32_t offset[4];
    for (int f = 0; f < 4; ++f) {
      EXPECT_EQ(r.str(), std::vector<std::string>({"x", "y", "z", "intensity"})[f]);
      offset[f] = r.get<uint32_t>();
      EXPECT_EQ(r.get<uint8_t>(), ros1::kFloat32);
      EXPECT_EQ(r.get<uint32_t>(), 1u);
    }
    EXPECT_EQ(r.get<uint8_t>(), 0);
    const uint32_t step = r.get<uint32_t>();
    EXPECT_EQ(r.get<uint32_t>(), step * n);
    ASSERT_EQ(r.get<uint32_t>(), step * n);
    const size_t data = r.at;
    for (int i = 0; i < n; ++i)
      for (int f = 0; f < 4; ++f) {
        float v;
        std::memcpy(&v, out.data() + data + size_t(step) * i + offset[f], 4);
        ASSERT_EQ(v, pts[i][f]) << "point " << i << " field " << f << " of " << n;
      }
    r.at = data + size_t(step) * n;
    EXPECT_EQ(r.get<uint8_t>(), 1);
    EXPECT_EQ(r.at, out.size()) << n << " points: bytes left over";
  }
}

TEST(Ros1PointCloud, TimeBeforeTheEpochIsZero) {
  std::string out;
  ros1::writePointCloud2(cloud(-5, 0, {}), "lidar", out);
  Reader r{out};
  r.get<uint32_t>();
  EXPECT_EQ(r.get<uint32_t>(), 0u);
  EXPECT_EQ(r.get<uint32_t>(), 0u);
}

// The definition names PointCloud2's fields in the order they are written, and each type it uses.
TEST(Ros1PointCloud, DefinitionListsTheFieldsInWireOrderAndTheTypesItUses) {
  const std::string& d = ros1::pointCloud2Definition();
  size_t at = 0;
  for (const char* line : {"std_msgs/Header header\n", "uint32 height\n", "uint32 width\n", "sensor_msgs/PointField[] fields\n",
                           "bool is_bigendian\n", "uint32 point_step\n", "uint32 row_step\n", "uint8[] data\n",
                           "bool is_dense\n", "MSG: std_msgs/Header\n", "uint32 seq\n", "time stamp\n",
                           "string frame_id\n", "MSG: sensor_msgs/PointField\n", "string name\n", "uint32 offset\n",
                           "uint8 datatype\n", "uint32 count\n"}) {
    const size_t found = d.find(line, at);
    ASSERT_NE(found, std::string::npos) << "'" << line << "' after offset " << at << " in\n" << d;
    at = found + std::strlen(line);
  }
  EXPECT_NE(d.find("\n" + std::string(80, '=') + "\nMSG: "), std::string::npos);
}

std::string lcmBytes(const point_cloud_t& m) {
  std::string b(static_cast<size_t>(m.getEncodedSize()), '\0');
  EXPECT_EQ(m.encode(b.data(), 0, static_cast<int>(b.size())), static_cast<int>(b.size()));
  return b;
}

// From LIDAR_SCAN's bytes: the same PointCloud2 as from the decoded message.
TEST(Ros1PointCloud, FromLcmBytesIsTheSameAsFromTheDecodedScan) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u(-80, 80);
  std::string a, b;
  for (int n : {0, 1, 3, 5000}) {
    std::vector<std::array<float, 4>> pts(n);
    for (auto& p : pts) p = {u(rng), u(rng), u(rng) / 20, std::abs(u(rng)) / 80};
    point_cloud_t m = cloud(987'654'321'000LL + n, 40 + n, pts);
    m.sequence = n % 2 ? "0007" : "a-longer-sequence-name";
    ros1::ScanId id;
    const std::string bytes = lcmBytes(m);
    const Refusal r = ros1::writePointCloud2FromLcm(bytes.data(), bytes.size(), "lidar", a, &id);
    ASSERT_FALSE(r) << r.reason << ": " << r.detail;
    ros1::writePointCloud2(m, "lidar", b);
    EXPECT_EQ(a, b) << n << " points";
    EXPECT_EQ(id.frame, 40 + n);
    EXPECT_EQ(id.utime, 987'654'321'000LL + n);
  }
}

// A scan the guard refuses is refused from its bytes too, for the same reason and detail.
TEST(Ros1PointCloud, FromLcmBytesRefusesWhatTheGuardRefuses) {
  const point_cloud_t good = cloud(1'000'000, 3, {{1, 2, 3, 0.5f}, {4, 5, 6, 0.25f}, {7, 8, 9, 1}});
  std::vector<std::pair<std::string, std::string>> cases;  // what, bytes
  point_cloud_t m = good;
  m.z[2] = std::numeric_limits<float>::quiet_NaN();
  cases.push_back({"NaN z", lcmBytes(m)});
  m = good;
  m.intensity[1] = std::numeric_limits<float>::infinity();
  cases.push_back({"infinite intensity", lcmBytes(m)});
  m = good;
  m.frame = kMaxFrame + 1;
  cases.push_back({"frame out of range", lcmBytes(m)});
  m = good;
  m.utime = -1;
  cases.push_back({"negative utime", lcmBytes(m)});
  cases.push_back({"truncated", lcmBytes(good).substr(0, 40)});
  cases.push_back({"trailing byte", lcmBytes(good) + "x"});
  std::string wrong_hash = lcmBytes(good);
  wrong_hash[0] ^= 1;
  cases.push_back({"another type", wrong_hash});
  for (const auto& [what, bytes] : cases) {
    point_cloud_t decoded;
    const Refusal guard = decodeChecked(bytes.data(), bytes.size(), &decoded);
    ASSERT_TRUE(guard) << what << ": the guard accepts it";
    std::string out;
    ros1::ScanId id;
    const Refusal ours = ros1::writePointCloud2FromLcm(bytes.data(), bytes.size(), "lidar", out, &id);
    EXPECT_EQ(ours.reason, guard.reason) << what;
    EXPECT_EQ(ours.detail, guard.detail) << what;
    const Refusal head = ros1::checkScanHeader(bytes.data(), bytes.size(), &id);
    if (what.find("NaN") == std::string::npos && what.find("infinite") == std::string::npos)
      EXPECT_EQ(head.reason, guard.reason) << what;  // the header check sees all but the points
    else
      EXPECT_FALSE(head) << what;
  }
}

// The converter picks the encoding: JSON for MCAP files, PointCloud2 for the live bridge.
TEST(Ros1PointCloud, ConverterWritesTheScanInTheChosenEncoding) {
  const point_cloud_t m = cloud(2'000'000, 3, {{1, 2, 3, 0.5f}});
  ConverterOptions opt;
  opt.scan_encoding = ScanEncoding::kRos1;
  Converter ros(Channels(), opt), json;
  std::vector<Output> a, b;
  const std::string bytes = lcmBytes(m);
  ASSERT_FALSE(ros.convert("LIDAR_SCAN", bytes.data(), bytes.size(), a));
  ASSERT_FALSE(json.convert("LIDAR_SCAN", bytes.data(), bytes.size(), b));
  ASSERT_EQ(a.size(), 1u);
  ASSERT_EQ(b.size(), 1u);
  const SchemaText& s = *ros.topics()[a[0].topic].schema;
  EXPECT_STREQ(s.name, "sensor_msgs/PointCloud2");
  EXPECT_STREQ(s.schema_encoding, "ros1msg");
  EXPECT_STREQ(s.message_encoding, "ros1");
  std::string want;
  ros1::writePointCloud2(m, "lidar", want);
  EXPECT_EQ(a[0].bytes, want);
  EXPECT_EQ(a[0].utime, 2'000'000);
  EXPECT_STREQ(json.topics()[b[0].topic].schema->name, "foxglove.PointCloud");
  EXPECT_STREQ(json.topics()[b[0].topic].schema->message_encoding, "json");
  EXPECT_EQ(b[0].bytes.front(), '{');
}

}  // namespace
