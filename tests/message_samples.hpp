// Valid messages of every type, their encodings and the malformed variants a hostile sender could
// publish: shared by the guard's unit test, the malformed-message process test and the
// fuzz corpus writer.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "dlslot/message_guard.hpp"

namespace dlslot::test {

using Bytes = std::vector<uint8_t>;

template <class Msg>
Bytes encode(const Msg& m) {
  Bytes b(m.getEncodedSize());
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

inline void putI32(Bytes& b, size_t at, int32_t v) {
  const auto u = static_cast<uint32_t>(v);
  for (int i = 0; i < 4; ++i) b.at(at + i) = static_cast<uint8_t>(u >> (24 - 8 * i));
}
inline int32_t getI32(const Bytes& b, size_t at) {
  uint32_t u = 0;
  for (int i = 0; i < 4; ++i) u = (u << 8) | b.at(at + i);
  return static_cast<int32_t>(u);
}
inline void putF64(Bytes& b, size_t at, double v) {
  uint64_t u;
  std::memcpy(&u, &v, 8);
  for (int i = 0; i < 8; ++i) b.at(at + i) = static_cast<uint8_t>(u >> (56 - 8 * i));
}
inline void putF32(Bytes& b, size_t at, float v) {
  uint32_t u;
  std::memcpy(&u, &v, 4);
  for (int i = 0; i < 4; ++i) b.at(at + i) = static_cast<uint8_t>(u >> (24 - 8 * i));
}

// Offsets in an encoding (hash 8, utime 8, frame 4 for frame-indexed types).
constexpr size_t kFrameAt = 16;

inline pose_t samplePose(double x) {
  pose_t p{};
  p.position[0] = x;
  p.position[1] = 1;
  p.position[2] = 0.5;
  p.orientation[0] = 1;
  return p;
}

inline box_t sampleBox(int id) {
  box_t b{};
  b.type = "Car";
  b.id = id;
  b.score = 1;
  b.center[0] = 10;
  b.size[0] = 4;
  b.size[1] = 1.8;
  b.size[2] = 1.5;
  return b;
}

inline stage_timing_t sampleTiming() { return stage_timing_t{"total", 2.5}; }

// Each sample ends with an empty array, so its last 4 bytes are that array's count, and has a
// string at a known offset (kString*): the two places the malformed variants patch.
inline point_cloud_t sampleScan(int frame) {
  point_cloud_t m{};
  m.utime = 1000 + frame;
  m.frame = frame;
  m.sequence = "0000";
  return m;  // num_points = 0
}
constexpr size_t kScanStringAt = 20;

inline detections_t sampleDetections(int frame) {
  detections_t m{};
  m.utime = 1000 + frame;
  m.frame = frame;
  m.source = "geometric";
  return m;  // num_boxes = 0
}
// The source string at 20 (9 characters), the count at 34.
constexpr size_t kDetectionsSourceAt = 20;
// With one box: its count at 34, the box's type string at 38.
inline detections_t sampleDetectionsWithBox(int frame) {
  detections_t m = sampleDetections(frame);
  m.boxes = {sampleBox(-1)};
  m.num_boxes = 1;
  return m;
}
constexpr size_t kDetectionsCountAt = 34, kDetectionsStringAt = 38;

inline ground_truth_t sampleGroundTruth(int frame) {
  ground_truth_t m{};
  m.utime = 1000 + frame;
  m.frame = frame;
  m.has_pose = true;
  m.pose = samplePose(frame);
  m.boxes = {sampleBox(1)};
  m.num_boxes = 1;
  return m;  // num_dontcare = 0
}
constexpr size_t kGroundTruthPoseAt = 21, kGroundTruthStringAt = 81;

inline odometry_t sampleOdometry(int frame) {
  odometry_t m{};
  m.utime = 1000 + frame;
  m.frame = frame;
  m.status_text = "ok";
  m.pose = samplePose(frame);
  m.delta = samplePose(1);
  return m;  // num_timings = 0
}
constexpr size_t kOdometryStringAt = 21, kOdometryPoseAt = 21 + 4 + 3 + 1;

inline associations_t sampleAssociations(int frame) {
  associations_t m{};
  m.utime = 1000 + frame;
  m.frame = frame;
  m.ego_pose = samplePose(frame);
  m.ego_pose_source = "odometry";
  association_t a{};
  a.track_id = 3;
  a.box_lidar = sampleBox(-1);
  a.box_world = sampleBox(-1);
  a.confidence = 0.5;
  m.associations = {a};
  m.num_associations = 1;
  return m;  // num_timings = 0
}
constexpr size_t kAssociationsPoseAt = 20, kAssociationsStringAt = 76;

// Where an encoded SLOT_STATE keeps num_timings (its last count): before an empty status_text
// (its length and terminating zero, 5 bytes) and the odometry check (int8, 3 doubles, int32):
// 34 bytes and the count's own 4 from the end.
inline size_t slotStateTimingsCountAt(const Bytes& encoded) { return encoded.size() - 4 - 34; }

inline slot_state_t sampleSlotState(int frame) {
  slot_state_t m{};
  m.utime = 1000 + frame;
  m.frame = frame;
  m.mode = "slot";
  m.ego_pose = samplePose(frame);
  m.smoothed_pose = samplePose(0);
  track_t t{};
  t.id = 3;
  t.type = "Car";
  t.pose = samplePose(5);
  t.size[0] = 4;
  t.size[1] = 1.8;
  t.size[2] = 1.5;
  t.last_seen_frame = frame;
  t.status = track_t::STATUS_CONFIRMED;
  t.confidence = 0.9;
  m.tracks = {t};
  m.num_tracks = 1;
  return m;  // num_timings = 0
}
constexpr size_t kSlotStringAt = 20, kSlotPoseAt = 20 + 4 + 5;

// A MAP_STATE without loop events (num_loops, the last field, 0), or with an accepted loop from
// `frame` to frame 0 and a refused one.
inline map_state_t sampleMapState(int frame, bool with_loops = false) {
  map_state_t m{};
  m.utime = 1000 + frame;
  m.frame = frame;
  m.map_from_world = samplePose(0.5);
  m.map_pose = samplePose(frame);
  m.keyframes = 3;
  m.map_points = 1000;
  if (with_loops) {
    loop_event_t accepted{};
    accepted.query_frame = frame;
    accepted.match_frame = 0;
    accepted.relative = samplePose(0.2);
    accepted.descriptor_distance = 0.2;
    accepted.inlier_ratio = 0.6;
    accepted.rmse_m = 0.15;
    accepted.accepted = true;
    loop_event_t refused = accepted;
    refused.accepted = false;
    refused.reason = "overlap";
    m.loops = {accepted, refused};
    m.loops_accepted = 1;
    m.loops_rejected = 1;
  }
  m.num_loops = static_cast<int32_t>(m.loops.size());
  return m;
}
constexpr size_t kMapStatePoseAt = 20;

inline process_status_t sampleStatus() {
  process_status_t m{};
  m.utime = 1000;
  m.name = "odometry";
  m.last_frame = 3;
  return m;  // num_counters = 0
}
constexpr size_t kStatusStringAt = 16;

// One malformed variant of an encoded message.
struct Malformed {
  std::string name;  // random | count_-1 | count_int32_max | count_beyond_data | string_length_-1 | ...
  Bytes bytes;
};

// The structural variants every type gets: the fingerprint followed by random bytes, the last
// array's count set to -1, INT32_MAX and a count larger than the data, the string at `string_at`
// given a length of -1 and 0, and the message cut short by one byte.
// (`count_at` 0: the last 4 bytes.)
inline std::vector<Malformed> structuralVariants(const Bytes& valid, size_t string_at, size_t count_at = 0,
                                                 uint32_t seed = 7) {
  std::vector<Malformed> out;
  std::mt19937 rng(seed);
  Bytes random(valid.begin(), valid.begin() + 8);
  for (int i = 0; i < 256; ++i) random.push_back(static_cast<uint8_t>(rng()));
  out.push_back({"random", random});
  if (count_at == 0) count_at = valid.size() - 4;
  for (const auto& [name, value] : std::vector<std::pair<std::string, int32_t>>{
           {"count_-1", -1}, {"count_int32_max", std::numeric_limits<int32_t>::max()}, {"count_beyond_data", 1000}}) {
    Bytes b = valid;
    putI32(b, count_at, value);
    out.push_back({name, b});
  }
  if (string_at > 0) {
    for (const auto& [name, value] :
         std::vector<std::pair<std::string, int32_t>>{{"string_length_-1", -1}, {"string_length_0", 0}}) {
      Bytes b = valid;
      putI32(b, string_at, value);
      out.push_back({name, b});
    }
  }
  out.push_back({"truncated", Bytes(valid.begin(), valid.end() - 1)});
  return out;
}

// The frame-number variants of a frame-indexed message: 10^9 and INT32_MAX.
inline std::vector<Malformed> frameVariants(const Bytes& valid) {
  std::vector<Malformed> out;
  for (const auto& [name, value] : std::vector<std::pair<std::string, int32_t>>{
           {"frame_1e9", 1000000000}, {"frame_int32_max", std::numeric_limits<int32_t>::max()}}) {
    Bytes b = valid;
    putI32(b, kFrameAt, value);
    out.push_back({name, b});
  }
  return out;
}

// A NaN in the first coordinate of the pose at `pose_at`.
inline Malformed nanPose(const Bytes& valid, size_t pose_at) {
  Bytes b = valid;
  putF64(b, pose_at, std::numeric_limits<double>::quiet_NaN());
  return {"nan_pose", b};
}

}  // namespace dlslot::test
