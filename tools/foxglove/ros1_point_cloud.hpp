// A scan as ROS 1's sensor_msgs/PointCloud2, the binary point encoding of the live bridge.
//
// JSON carries a point cloud's bytes as base64 (a third larger, and a pass over every byte on
// both ends); Foxglove's WebSocket protocol lets a channel declare another message encoding, and
// Foxglove reads ROS 1 messages ("ros1", schema encoding "ros1msg": the message definition text)
// without ROS. ROS 1 serialization is the simplest binary encoding Foxglove reads: little-endian
// fields in declaration order, no alignment, arrays and strings prefixed by a uint32 count, no
// framing. The points go as one uint8[] of interleaved float32 x, y, z, intensity (16 bytes a
// point), the same layout as the JSON foxglove.PointCloud of the MCAP export.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>

#include "dlslot/message_guard.hpp"
#include "dlslot/point_cloud_t.hpp"

namespace dlslot::foxglove::ros1 {

// Appends ROS 1 serialized fields to a byte string (x86 and ARM are little-endian, as ROS 1 is).
class Writer {
 public:
  explicit Writer(std::string& out) : out_(out) {}
  void u8(uint8_t v) { out_.push_back(static_cast<char>(v)); }
  void u32(uint32_t v) { raw(&v, 4); }
  void f32(float v) { raw(&v, 4); }
  // uint32 length, then the bytes (no terminating NUL).
  void string(std::string_view s) {
    u32(static_cast<uint32_t>(s.size()));
    out_.append(s.data(), s.size());
  }
  // time: uint32 sec, uint32 nsec; a negative time is written as 0 (ROS 1 time is unsigned).
  void time(int64_t utime_us);
  // Reserves `n` bytes at the end and returns where they start, for a caller that fills them.
  char* grow(size_t n) {
    const size_t at = out_.size();
    out_.resize(at + n);
    return &out_[at];
  }

 private:
  void raw(const void* p, size_t n) { out_.append(static_cast<const char*>(p), n); }
  std::string& out_;
};

// The schema's name and its ros1msg text: PointCloud2's definition, then each type it uses
// after a line of '=' and "MSG: pkg/Type" (the concatenation rosbag and MCAP store).
inline constexpr const char* kPointCloud2 = "sensor_msgs/PointCloud2";
const std::string& pointCloud2Definition();

// sensor_msgs/PointField datatype of float32.
inline constexpr uint8_t kFloat32 = 7;
inline constexpr uint32_t kPointStep = 16;

// Writes `scan` as a PointCloud2 into `out` (replacing its contents, keeping its capacity):
// header {seq = frame, stamp = utime, frame_id}, height 1, width num_points, fields x y z
// intensity (float32 at 0, 4, 8, 12), little-endian, point_step 16, row_step 16 * width, the
// points, is_dense (the message guard lets no non-finite point through).
void writePointCloud2(const point_cloud_t& scan, std::string_view frame_id, std::string& out);

// The same PointCloud2 straight from LIDAR_SCAN's LCM bytes (an encoded point_cloud_t), in one
// pass over the points: lcm-gen's decoder would first copy them into four vectors, one byte at a
// time, and the guard would read them once more for finiteness. The message is checked as the
// guard checks it (message_guard.hpp): its layout (checkLayout), its frame and utime (checkContent
// on its scalar fields) and every point finite, with the guard's refusal reasons; on a refusal
// `out` holds nothing meant for use. `id` gets the scan's frame and utime.
struct ScanId {
  int frame = -1;
  int64_t utime = -1;
};
Refusal writePointCloud2FromLcm(const void* data, size_t size, std::string_view frame_id, std::string& out, ScanId* id);
// Only the checks of writePointCloud2FromLcm short of the points (layout, frame, utime): for a
// scan nobody watches.
Refusal checkScanHeader(const void* data, size_t size, ScanId* id);

}  // namespace dlslot::foxglove::ros1
