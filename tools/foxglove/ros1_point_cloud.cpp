#include "ros1_point_cloud.hpp"

#include <algorithm>

namespace dlslot::foxglove::ros1 {

static_assert(sizeof(float) == 4 && sizeof(uint32_t) == 4, "ROS 1 float32 / uint32");
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "ROS 1 serialization is little-endian: Writer copies values as they are in memory"
#endif

void Writer::time(int64_t utime_us) {
  const int64_t us = utime_us < 0 ? 0 : utime_us;
  u32(static_cast<uint32_t>(us / 1000000));
  u32(static_cast<uint32_t>((us % 1000000) * 1000));
}

const std::string& pointCloud2Definition() {
  static const std::string sep = "\n" + std::string(80, '=') + "\n";
  static const std::string text =
      "std_msgs/Header header\n"
      "uint32 height\n"
      "uint32 width\n"
      "sensor_msgs/PointField[] fields\n"
      "bool is_bigendian\n"
      "uint32 point_step\n"
      "uint32 row_step\n"
      "uint8[] data\n"
      "bool is_dense" +
      sep +
      "MSG: std_msgs/Header\n"
      "uint32 seq\n"
      "time stamp\n"
      "string frame_id" +
      sep +
      "MSG: sensor_msgs/PointField\n"
      "uint8 INT8=1\n"
      "uint8 UINT8=2\n"
      "uint8 INT16=3\n"
      "uint8 UINT16=4\n"
      "uint8 INT32=5\n"
      "uint8 UINT32=6\n"
      "uint8 FLOAT32=7\n"
      "uint8 FLOAT64=8\n"
      "string name\n"
      "uint32 offset\n"
      "uint8 datatype\n"
      "uint32 count\n";
  return text;
}

namespace {

// Everything before the points, ending with the data array's length.
void writeHead(Writer& w, int frame, int64_t utime, std::string_view frame_id, size_t n) {
  w.u32(static_cast<uint32_t>(frame));  // header.seq
  w.time(utime);
  w.string(frame_id);
  w.u32(1);                               // height: an unordered cloud is one row
  w.u32(static_cast<uint32_t>(n));        // width
  static constexpr const char* kNames[4] = {"x", "y", "z", "intensity"};
  w.u32(4);
  for (uint32_t f = 0; f < 4; ++f) {
    w.string(kNames[f]);
    w.u32(4 * f);     // offset
    w.u8(kFloat32);   // datatype
    w.u32(1);         // count
  }
  w.u8(0);  // is_bigendian
  w.u32(kPointStep);
  w.u32(static_cast<uint32_t>(kPointStep * n));  // row_step
  w.u32(static_cast<uint32_t>(kPointStep * n));  // data: uint8[] length
}

uint32_t be32(const uint8_t* p) {
  uint32_t v;
  std::memcpy(&v, p, 4);
  return __builtin_bswap32(v);
}

// An encoded point_cloud_t whose layout checked: hash (8), utime (8), frame (4), sequence (int32
// length counting its NUL, the bytes), num_points (4), then x[n] y[n] z[n] intensity[n], all
// big-endian (LCM's wire format).
struct LcmScan {
  point_cloud_t head;       // the scalar fields; no points
  const uint8_t* points;    // x[n], then y, z, intensity
  size_t n;
};

Refusal parseScan(const void* data, size_t size, LcmScan* s) {
  if (Refusal r = checkLayout(static_cast<const point_cloud_t*>(nullptr), data, size)) return r;
  const auto* p = static_cast<const uint8_t*>(data);
  s->head.utime = static_cast<int64_t>((uint64_t{be32(p + 8)} << 32) | be32(p + 12));
  s->head.frame = static_cast<int32_t>(be32(p + 16));
  const uint32_t seq_len = be32(p + 20);  // >= 1: the layout check refuses less
  s->head.sequence.assign(reinterpret_cast<const char*>(p + 24), seq_len - 1);
  s->head.num_points = 0;
  s->n = be32(p + 24 + seq_len);
  s->points = p + 28 + seq_len;
  return checkContent(s->head);
}

}  // namespace

void writePointCloud2(const point_cloud_t& scan, std::string_view frame_id, std::string& out) {
  out.clear();
  // The guard makes every array num_points long; the smallest bounds the loop whatever the input.
  size_t n = scan.num_points > 0 ? static_cast<size_t>(scan.num_points) : 0;
  for (const auto* a : {&scan.x, &scan.y, &scan.z, &scan.intensity}) n = std::min(n, a->size());
  out.reserve(128 + frame_id.size() + kPointStep * n);
  Writer w(out);
  writeHead(w, scan.frame, scan.utime, frame_id, n);
  // The LCM message keeps one array per field; PointCloud2 interleaves them point by point.
  char* p = w.grow(kPointStep * n);
  const float* arrays[4] = {scan.x.data(), scan.y.data(), scan.z.data(), scan.intensity.data()};
  for (size_t i = 0; i < n; ++i, p += kPointStep) {
    const float v[4] = {arrays[0][i], arrays[1][i], arrays[2][i], arrays[3][i]};
    std::memcpy(p, v, kPointStep);
  }
  w.u8(1);  // is_dense: every point finite
}

Refusal checkScanHeader(const void* data, size_t size, ScanId* id) {
  LcmScan s;
  const Refusal r = parseScan(data, size, &s);
  if (!r) *id = {s.head.frame, s.head.utime};
  return r;
}

Refusal writePointCloud2FromLcm(const void* data, size_t size, std::string_view frame_id, std::string& out, ScanId* id) {
  LcmScan s;
  if (Refusal r = parseScan(data, size, &s)) return r;
  *id = {s.head.frame, s.head.utime};
  const size_t n = s.n;
  out.clear();
  out.reserve(128 + frame_id.size() + kPointStep * n);
  Writer w(out);
  writeHead(w, s.head.frame, s.head.utime, frame_id, n);
  char* d = w.grow(kPointStep * n);
  // Byte-swapped and interleaved; a float is finite unless its exponent bits are all ones.
  uint32_t not_finite = 0;
  for (size_t i = 0; i < n; ++i)
    for (size_t f = 0; f < 4; ++f) {
      const uint32_t v = be32(s.points + 4 * (f * n + i));
      not_finite |= static_cast<uint32_t>((v & 0x7F800000u) == 0x7F800000u);
      std::memcpy(d + kPointStep * i + 4 * f, &v, 4);
    }
  if (not_finite) {  // the guard's refusal: the first such value, field by field
    for (size_t f = 0; f < 4; ++f)
      for (size_t i = 0; i < n; ++i)
        if ((be32(s.points + 4 * (f * n + i)) & 0x7F800000u) == 0x7F800000u)
          return {"non_finite", "point[" + std::to_string(i) + "]: expected a finite number"};
  }
  w.u8(1);  // is_dense: every point finite
  return {};
}

}  // namespace dlslot::foxglove::ros1
