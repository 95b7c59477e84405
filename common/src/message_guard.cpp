#include "dlslot/message_guard.hpp"

#include <cmath>
#include <cstring>
#include <limits>

namespace dlslot {
namespace {

// ---------------- layout: a walk over the encoded bytes that allocates nothing ----------------

// Encoded sizes of LCM's fixed-size fields (big-endian, booleans and int8 one byte).
constexpr size_t kI8 = 1, kI32 = 4, kI64 = 8, kF32 = 4, kF64 = 8;
constexpr size_t kPose = 7 * kF64;
constexpr size_t kMinString = kI32 + 1;  // length (>= 1) and the terminating NUL
constexpr size_t kMinBox = kMinString + kI32 + 8 * kF64;
constexpr size_t kMinTiming = kMinString + kF64;
constexpr size_t kMinTrack = kI32 + kMinString + kPose + 18 * kF64 + kI8 + 36 * kF64 + 3 * kI32 + kI8 + kF64;
constexpr size_t kMinLoopEvent = 2 * kI32 + kPose + 3 * kF64 + kI8 + kMinString;
constexpr size_t kMinAssociation = 3 * kI32 + kI8 + 2 * kMinBox + kI8 + 3 * kF64 + kI8 + kF64 + kI8 + kF64;

class Cursor {
 public:
  Cursor(const void* data, size_t size) : b_(static_cast<const uint8_t*>(data)), size_(size) {}

  bool fingerprint(int64_t expected) {
    int64_t h = 0;
    if (!i64(&h)) return false;
    if (h != expected) return fail("fingerprint", "not this message type (fingerprint differs)");
    return true;
  }
  bool skip(size_t n, const char* field) {
    if (n > left()) return fail("truncated", std::string(field) + ": needs " + std::to_string(n) + " bytes, " +
                                                 std::to_string(left()) + " left");
    pos_ += n;
    return true;
  }
  bool i32(int32_t* v, const char* field = "int32") {
    if (!need(kI32, field)) return false;
    *v = static_cast<int32_t>((uint32_t(b_[pos_]) << 24) | (uint32_t(b_[pos_ + 1]) << 16) |
                              (uint32_t(b_[pos_ + 2]) << 8) | uint32_t(b_[pos_ + 3]));
    pos_ += kI32;
    return true;
  }
  bool i64(int64_t* v) {
    if (!need(kI64, "int64")) return false;
    uint64_t u = 0;
    for (int i = 0; i < 8; ++i) u = (u << 8) | b_[pos_ + i];
    *v = static_cast<int64_t>(u);
    pos_ += kI64;
    return true;
  }
  // An array count: >= 0, and `count` elements of at least `min_element` bytes fit in what is left.
  bool count(int32_t* n, size_t min_element, const char* field) {
    if (!i32(n, field)) return false;
    if (*n < 0) return fail("bad_count", std::string(field) + " = " + std::to_string(*n) + ", expected >= 0");
    if (static_cast<uint64_t>(*n) * min_element > left())
      return fail("bad_count", std::string(field) + " = " + std::to_string(*n) + " needs at least " +
                                   std::to_string(static_cast<uint64_t>(*n) * min_element) + " bytes, " +
                                   std::to_string(left()) + " left");
    return true;
  }
  // A string: its length counts the NUL, so >= 1, and it must fit.
  bool str(const char* field) {
    int32_t len = 0;
    if (!i32(&len, field)) return false;
    if (len < 1) return fail("bad_string", std::string(field) + ": string length " + std::to_string(len) + ", expected >= 1");
    if (static_cast<size_t>(len) > left())
      return fail("bad_string", std::string(field) + ": string length " + std::to_string(len) + ", " +
                                    std::to_string(left()) + " bytes left");
    // One NUL, at the end: lcm-gen's encoder writes a string up to its first NUL, so one with a NUL
    // inside would not encode back to what was decoded (found by fuzz_msg_*).
    const void* nul = std::memchr(b_ + pos_, 0, static_cast<size_t>(len));
    if (nul != b_ + pos_ + len - 1)
      return fail("bad_string", std::string(field) + ": expected one NUL, at the end of the string");
    pos_ += static_cast<size_t>(len);
    return true;
  }
  // The message ends where its last field does.
  Refusal finish() {
    if (refusal_) return refusal_;
    if (pos_ != size_) return {"trailing_bytes", std::to_string(size_ - pos_) + " bytes after the last field"};
    return {};
  }
  bool fail(const char* reason, std::string detail) {
    if (!refusal_) refusal_ = {reason, std::move(detail)};
    return false;
  }

 private:
  size_t left() const { return size_ - pos_; }
  bool need(size_t n, const char* field) {
    if (n <= left()) return true;
    return fail("truncated", std::string(field) + ": message ends " + std::to_string(n - left()) + " bytes early");
  }
  const uint8_t* b_;
  size_t size_, pos_ = 0;
  Refusal refusal_;
};

bool pose(Cursor& c, const char* field) { return c.skip(kPose, field); }

bool box(Cursor& c) { return c.str("box.type") && c.skip(kI32 + 8 * kF64, "box"); }

bool boxes(Cursor& c, const char* count_field) {
  int32_t n = 0;
  if (!c.count(&n, kMinBox, count_field)) return false;
  for (int32_t i = 0; i < n; ++i)
    if (!box(c)) return false;
  return true;
}

bool timings(Cursor& c) {
  int32_t n = 0;
  if (!c.count(&n, kMinTiming, "num_timings")) return false;
  for (int32_t i = 0; i < n; ++i)
    if (!c.str("timings.name") || !c.skip(kF64, "timings.ms")) return false;
  return true;
}

bool track(Cursor& c) {
  return c.skip(kI32, "track.id") && c.str("track.type") && pose(c, "track.pose") &&
         c.skip(18 * kF64 + kI8 + 36 * kF64 + 3 * kI32 + kI8 + kF64, "track");
}

bool association(Cursor& c) {
  return c.skip(3 * kI32 + kI8, "association") && box(c) && box(c) &&
         c.skip(kI8 + 3 * kF64 + kI8 + kF64 + kI8 + kF64, "association");
}

// The header every frame-indexed message starts with: fingerprint, utime, frame.
bool header(Cursor& c, int64_t hash) { return c.fingerprint(hash) && c.skip(kI64 + kI32, "utime, frame"); }

// ---------------- content ----------------

bool finite(const double* v, size_t n) {
  for (size_t i = 0; i < n; ++i)
    if (!std::isfinite(v[i])) return false;
  return true;
}

std::string fieldAt(const char* field, size_t i) { return std::string(field) + "[" + std::to_string(i) + "]"; }

Refusal nonFinite(const std::string& field) { return {"non_finite", field + ": expected a finite number"}; }

Refusal checkFrame(int frame, const char* field = "frame") {
  if (frame < 0 || frame > kMaxFrame)
    return {"frame_range", std::string(field) + " = " + std::to_string(frame) + ", expected 0.." + std::to_string(kMaxFrame)};
  return {};
}

Refusal checkUtime(int64_t utime) {
  if (utime < 0) return {"bad_value", "utime = " + std::to_string(utime) + ", expected >= 0"};
  return {};
}

// A rigid transform: finite, with a unit quaternion (LCM carries what the sender normalised).
Refusal checkPose(const pose_t& p, const std::string& field) {
  if (!finite(p.position, 3)) return nonFinite(field + ".position");
  if (!finite(p.orientation, 4)) return nonFinite(field + ".orientation");
  const double n = std::sqrt(p.orientation[0] * p.orientation[0] + p.orientation[1] * p.orientation[1] +
                             p.orientation[2] * p.orientation[2] + p.orientation[3] * p.orientation[3]);
  if (std::abs(n - 1.0) > 1e-3)
    return {"bad_quaternion", field + ".orientation has norm " + std::to_string(n) + ", expected 1"};
  return {};
}

Refusal checkFinite(const double* v, size_t n, const std::string& field) {
  for (size_t i = 0; i < n; ++i)
    if (!std::isfinite(v[i])) return nonFinite(field + "[" + std::to_string(i) + "]");
  return {};
}

Refusal checkCount(int32_t value, size_t actual, const char* field) {
  if (value < 0 || static_cast<size_t>(value) != actual)
    return {"bad_count", std::string(field) + " = " + std::to_string(value) + ", expected the array's " +
                             std::to_string(actual)};
  return {};
}

Refusal checkNonNegative(int64_t value, const char* field) {
  if (value < 0) return {"bad_value", std::string(field) + " = " + std::to_string(value) + ", expected >= 0"};
  return {};
}

Refusal checkTimings(const std::vector<stage_timing_t>& timings) {
  for (size_t i = 0; i < timings.size(); ++i)
    if (!std::isfinite(timings[i].ms) || timings[i].ms < 0)
      return {"bad_value", fieldAt("timings", i) + ".ms = " + std::to_string(timings[i].ms) + ", expected finite >= 0"};
  return {};
}

// A labelled box: finite, positive size, a track id >= 0 (-1 when unknown).
Refusal checkLabelBox(const box_t& b, const std::string& field, bool allow_empty) {
  if (!std::isfinite(b.score)) return nonFinite(field + ".score");
  if (Refusal r = checkFinite(b.center, 3, field + ".center")) return r;
  if (Refusal r = checkFinite(b.size, 3, field + ".size")) return r;
  if (!std::isfinite(b.yaw)) return nonFinite(field + ".yaw");
  for (int k = 0; k < 3; ++k)
    if (b.size[k] < 0 || (!allow_empty && b.size[k] == 0))
      return {"bad_size", field + ".size[" + std::to_string(k) + "] = " + std::to_string(b.size[k]) + ", expected > 0"};
  if (b.id < -1) return {"bad_value", field + ".id = " + std::to_string(b.id) + ", expected >= -1"};
  return {};
}

// A detected box (DETECTIONS, the boxes of ASSOCIATIONS): finite, every size > 0 (a detector
// finds no object without extent), a track id >= -1.
Refusal checkDetectedBox(const box_t& b, const std::string& field) { return checkLabelBox(b, field, false); }

Refusal checkStatus(int8_t status, int max, const std::string& field) {
  if (status < 0 || status > max)
    return {"bad_enum", field + " = " + std::to_string(status) + ", expected 0.." + std::to_string(max)};
  return {};
}

Refusal checkConfidence(double c, const std::string& field) {
  if (!std::isfinite(c) || c < 0 || c > 1)
    return {"bad_value", field + " = " + std::to_string(c) + ", expected a number in [0, 1]"};
  return {};
}

}  // namespace

// ---------------- layouts ----------------

Refusal checkLayout(const point_cloud_t*, const void* data, size_t size) {
  Cursor c(data, size);
  int32_t n = 0;
  (void)(header(c, point_cloud_t::getHash()) && c.str("sequence") && c.count(&n, 4 * kF32, "num_points") &&
         c.skip(4 * kF32 * static_cast<size_t>(n), "points"));
  return c.finish();
}

Refusal checkLayout(const detections_t*, const void* data, size_t size) {
  Cursor c(data, size);
  (void)(header(c, detections_t::getHash()) && c.str("source") && boxes(c, "num_boxes") && timings(c));
  return c.finish();
}

Refusal checkLayout(const ground_truth_t*, const void* data, size_t size) {
  Cursor c(data, size);
  (void)(header(c, ground_truth_t::getHash()) && c.skip(kI8, "has_pose") && pose(c, "pose") &&
         boxes(c, "num_boxes") && boxes(c, "num_dontcare"));
  return c.finish();
}

Refusal checkLayout(const odometry_t*, const void* data, size_t size) {
  Cursor c(data, size);
  (void)(header(c, odometry_t::getHash()) && c.skip(kI8, "status") && c.str("status_text") &&
         c.skip(kI8 + 2 * kPose + 37 * kF64 + 6 * kI32 + kF64 + kI32, "odometry") && timings(c));
  return c.finish();
}

Refusal checkLayout(const associations_t*, const void* data, size_t size) {
  Cursor c(data, size);
  int32_t n = 0;
  bool ok = header(c, associations_t::getHash()) && pose(c, "ego_pose") && c.str("ego_pose_source") &&
            c.skip(2 * kI32, "num_active_tracks, num_rejected") && c.count(&n, kMinAssociation, "num_associations");
  for (int32_t i = 0; ok && i < n; ++i) ok = association(c);
  (void)(ok && timings(c));
  return c.finish();
}

Refusal checkLayout(const slot_state_t*, const void* data, size_t size) {
  Cursor c(data, size);
  int32_t n = 0;
  bool ok = header(c, slot_state_t::getHash()) && c.str("mode") && pose(c, "ego_pose") &&
            c.skip(36 * kF64 + kI8 + kI32 + kI64, "ego_covariance, smoothed") && pose(c, "smoothed_pose") &&
            c.skip(2 * kI8, "missing flags") && c.count(&n, kMinTrack, "num_tracks");
  for (int32_t i = 0; ok && i < n; ++i) ok = track(c);
  (void)(ok && c.skip(kI32 + 2 * kF64, "iterations, costs") && timings(c) &&
         c.str("status_text") && c.skip(kI8 + 3 * kF64 + kI32, "odometry check"));
  return c.finish();
}

Refusal checkLayout(const process_status_t*, const void* data, size_t size) {
  Cursor c(data, size);
  int32_t n = 0;
  bool ok = c.fingerprint(process_status_t::getHash()) && c.skip(kI64, "utime") && c.str("name") &&
            c.skip(kI32 + kI64 + kI32 + 3 * kF64 + 4 * kI64, "status") && c.str("last_warning") &&
            c.count(&n, kMinString + kI64, "num_counters");
  for (int32_t i = 0; ok && i < n; ++i) ok = c.str("counter_names");
  (void)(ok && c.skip(kI64 * static_cast<size_t>(n), "counter_values"));
  return c.finish();
}

Refusal checkLayout(const run_event_t*, const void* data, size_t size) {
  Cursor c(data, size);
  (void)(c.fingerprint(run_event_t::getHash()) && c.skip(kI64, "utime") && c.str("event") &&
         c.skip(kI32, "first_frame") && c.str("sequence"));
  return c.finish();
}

Refusal checkLayout(const map_state_t*, const void* data, size_t size) {
  Cursor c(data, size);
  int32_t n = 0;
  bool ok = header(c, map_state_t::getHash()) && pose(c, "map_from_world") && pose(c, "map_pose") &&
            c.skip(5 * kI32, "keyframes .. loops_rejected") && c.count(&n, kMinLoopEvent, "num_loops");
  for (int32_t i = 0; ok && i < n; ++i)
    ok = c.skip(2 * kI32, "loops.frames") && pose(c, "loops.relative") && c.skip(3 * kF64 + kI8, "loops.scores") &&
         c.str("loops.reason");
  return c.finish();
}

// ---------------- contents ----------------

Refusal checkContent(const point_cloud_t& m) {
  if (Refusal r = checkFrame(m.frame)) return r;
  if (Refusal r = checkUtime(m.utime)) return r;
  const std::vector<float>* arrays[] = {&m.x, &m.y, &m.z, &m.intensity};
  for (const std::vector<float>* a : arrays) {
    if (Refusal r = checkCount(m.num_points, a->size(), "num_points")) return r;
    for (size_t i = 0; i < a->size(); ++i)
      if (!std::isfinite((*a)[i])) return nonFinite(fieldAt("point", i));
  }
  return {};
}

Refusal checkContent(const detections_t& m) {
  if (Refusal r = checkFrame(m.frame)) return r;
  if (Refusal r = checkUtime(m.utime)) return r;
  for (size_t i = 0; i < m.boxes.size(); ++i)
    if (Refusal r = checkDetectedBox(m.boxes[i], fieldAt("boxes", i))) return r;
  return checkTimings(m.timings);
}

Refusal checkContent(const ground_truth_t& m) {
  if (Refusal r = checkFrame(m.frame)) return r;
  if (Refusal r = checkUtime(m.utime)) return r;
  if (m.has_pose)
    if (Refusal r = checkPose(m.pose, "pose")) return r;
  for (size_t i = 0; i < m.boxes.size(); ++i)
    if (Refusal r = checkLabelBox(m.boxes[i], fieldAt("boxes", i), false)) return r;
  for (size_t i = 0; i < m.dontcare.size(); ++i)  // DontCare regions may have no 3D extent (size 0)
    if (Refusal r = checkLabelBox(m.dontcare[i], fieldAt("dontcare", i), true)) return r;
  return {};
}

Refusal checkContent(const odometry_t& m) {
  if (Refusal r = checkFrame(m.frame)) return r;
  if (Refusal r = checkUtime(m.utime)) return r;
  if (Refusal r = checkStatus(m.status, odometry_t::STATUS_FIRST_FRAME, "status")) return r;
  if (Refusal r = checkPose(m.pose, "pose")) return r;
  if (Refusal r = checkPose(m.delta, "delta")) return r;
  if (Refusal r = checkFinite(m.covariance, 36, "covariance")) return r;
  if (!std::isfinite(m.min_eigenvalue)) return nonFinite("min_eigenvalue");
  if (!std::isfinite(m.residual_mean)) return nonFinite("residual_mean");
  const std::pair<int32_t, const char*> counts[] = {
      {m.num_points_in, "num_points_in"}, {m.num_points_removed, "num_points_removed"}, {m.num_edge, "num_edge"},
      {m.num_plane, "num_plane"},         {m.num_map_edge, "num_map_edge"},             {m.num_map_plane, "num_map_plane"},
      {m.num_correspondences, "num_correspondences"}};
  for (const auto& [v, name] : counts)
    if (Refusal r = checkNonNegative(v, name)) return r;
  return checkTimings(m.timings);
}

Refusal checkContent(const associations_t& m) {
  if (Refusal r = checkFrame(m.frame)) return r;
  if (Refusal r = checkUtime(m.utime)) return r;
  if (Refusal r = checkPose(m.ego_pose, "ego_pose")) return r;
  if (Refusal r = checkNonNegative(m.num_active_tracks, "num_active_tracks")) return r;
  if (Refusal r = checkNonNegative(m.num_rejected, "num_rejected")) return r;
  for (size_t i = 0; i < m.associations.size(); ++i) {
    const association_t& a = m.associations[i];
    const std::string f = fieldAt("associations", i);
    if (Refusal r = checkNonNegative(a.detection_index, "associations.detection_index")) return r;
    if (Refusal r = checkNonNegative(a.track_id, "associations.track_id")) return r;
    if (Refusal r = checkNonNegative(a.num_observations, "associations.num_observations")) return r;
    if (Refusal r = checkDetectedBox(a.box_lidar, f + ".box_lidar")) return r;
    if (Refusal r = checkDetectedBox(a.box_world, f + ".box_world")) return r;
    if (a.has_prediction)
      if (Refusal r = checkFinite(a.predicted, 3, f + ".predicted")) return r;
    if (!std::isfinite(a.displacement)) return nonFinite(f + ".displacement");
    if (Refusal r = checkStatus(a.status, association_t::STATUS_COASTING, f + ".status")) return r;
    if (Refusal r = checkConfidence(a.confidence, f + ".confidence")) return r;
  }
  return checkTimings(m.timings);
}

Refusal checkContent(const slot_state_t& m) {
  if (Refusal r = checkFrame(m.frame)) return r;
  if (Refusal r = checkUtime(m.utime)) return r;
  if (Refusal r = checkPose(m.ego_pose, "ego_pose")) return r;
  if (Refusal r = checkFinite(m.ego_covariance, 36, "ego_covariance")) return r;
  if (m.has_smoothed) {
    if (Refusal r = checkFrame(m.smoothed_frame, "smoothed_frame")) return r;
    if (m.smoothed_frame > m.frame)
      return {"frame_range", "smoothed_frame = " + std::to_string(m.smoothed_frame) + ", expected <= frame " +
                                 std::to_string(m.frame)};
    if (Refusal r = checkPose(m.smoothed_pose, "smoothed_pose")) return r;
  }
  for (size_t i = 0; i < m.tracks.size(); ++i) {
    const track_t& t = m.tracks[i];
    const std::string f = fieldAt("tracks", i);
    if (Refusal r = checkNonNegative(t.id, "tracks.id")) return r;
    if (Refusal r = checkPose(t.pose, f + ".pose")) return r;
    if (Refusal r = checkFinite(t.size, 3, f + ".size")) return r;
    for (int k = 0; k < 3; ++k)
      if (t.size[k] <= 0)
        return {"bad_size", f + ".size[" + std::to_string(k) + "] = " + std::to_string(t.size[k]) + ", expected > 0"};
    if (Refusal r = checkFinite(t.velocity, 3, f + ".velocity")) return r;
    if (Refusal r = checkFinite(t.velocity_covariance, 9, f + ".velocity_covariance")) return r;
    if (Refusal r = checkFinite(t.angular_velocity, 3, f + ".angular_velocity")) return r;
    if (Refusal r = checkFinite(t.covariance, 36, f + ".covariance")) return r;
    if (Refusal r = checkNonNegative(t.age, "tracks.age")) return r;
    if (Refusal r = checkNonNegative(t.num_observations, "tracks.num_observations")) return r;
    // Not after this frame; before it by at most kMaxFrame (`frame - last_seen_frame` cannot overflow).
    if (t.last_seen_frame < -kMaxFrame || t.last_seen_frame > m.frame)
      return {"frame_range", f + ".last_seen_frame = " + std::to_string(t.last_seen_frame) + ", expected " +
                                 std::to_string(-kMaxFrame) + ".." + std::to_string(m.frame)};
    if (Refusal r = checkStatus(t.status, track_t::STATUS_COASTING, f + ".status")) return r;
    if (Refusal r = checkConfidence(t.confidence, f + ".confidence")) return r;
  }
  if (Refusal r = checkNonNegative(m.iterations, "iterations")) return r;
  if (!std::isfinite(m.initial_cost)) return nonFinite("initial_cost");
  if (!std::isfinite(m.final_cost)) return nonFinite("final_cost");
  if (Refusal r = checkStatus(m.odometry_check, slot_state_t::ODOMETRY_DISAGREED, "odometry_check")) return r;
  if (!std::isfinite(m.odometry_chi2)) return nonFinite("odometry_chi2");
  if (!std::isfinite(m.odometry_disagreement_m)) return nonFinite("odometry_disagreement_m");
  if (!std::isfinite(m.odometry_inflation)) return nonFinite("odometry_inflation");
  if (Refusal r = checkNonNegative(m.odometry_support, "odometry_support")) return r;
  return checkTimings(m.timings);
}

Refusal checkContent(const map_state_t& m) {
  if (Refusal r = checkFrame(m.frame)) return r;
  if (Refusal r = checkUtime(m.utime)) return r;
  if (Refusal r = checkPose(m.map_from_world, "map_from_world")) return r;
  if (Refusal r = checkPose(m.map_pose, "map_pose")) return r;
  const std::pair<int64_t, const char*> counts[] = {{m.keyframes, "keyframes"},
                                                    {m.map_points, "map_points"},
                                                    {m.removed_points, "removed_points"},
                                                    {m.loops_accepted, "loops_accepted"},
                                                    {m.loops_rejected, "loops_rejected"}};
  for (const auto& [value, field] : counts)
    if (Refusal r = checkNonNegative(value, field)) return r;
  for (size_t i = 0; i < m.loops.size(); ++i) {
    const loop_event_t& e = m.loops[i];
    const std::string f = fieldAt("loops", i);
    // A loop joins a scan of this frame or before to an older one.
    if (e.query_frame < 0 || e.query_frame > m.frame || e.match_frame < 0 || e.match_frame >= e.query_frame)
      return {"frame_range", f + ": match_frame " + std::to_string(e.match_frame) + ", query_frame " +
                                 std::to_string(e.query_frame) + ", expected 0 <= match < query <= frame " +
                                 std::to_string(m.frame)};
    if (Refusal r = checkPose(e.relative, f + ".relative")) return r;
    const std::pair<double, const char*> scores[] = {
        {e.descriptor_distance, ".descriptor_distance"}, {e.inlier_ratio, ".inlier_ratio"}, {e.rmse_m, ".rmse_m"}};
    for (const auto& [value, field] : scores)
      if (!std::isfinite(value) || value < 0)
        return {"bad_value", f + field + " = " + std::to_string(value) + ", expected finite >= 0"};
  }
  return {};
}

Refusal checkContent(const process_status_t& m) {
  if (m.name.empty()) return {"bad_value", "name: expected a process name"};
  if (m.last_frame < -1 || m.last_frame > kMaxFrame)
    return {"frame_range", "last_frame = " + std::to_string(m.last_frame) + ", expected -1.." + std::to_string(kMaxFrame)};
  const double times[] = {m.time_mean_ms, m.time_p95_ms, m.time_max_ms};
  if (Refusal r = checkFinite(times, 3, "time_ms")) return r;
  const std::pair<int64_t, const char*> counts[] = {{m.frames_handled, "frames_handled"}, {m.decode_errors, "decode_errors"},
                                                    {m.frame_gaps, "frame_gaps"},         {m.timeouts, "timeouts"},
                                                    {m.errors, "errors"}};
  for (const auto& [v, name] : counts)
    if (Refusal r = checkNonNegative(v, name)) return r;
  // Every counter counts something (frames, messages, bytes): a negative one would turn the
  // frame accounting's sums around.
  for (size_t i = 0; i < m.counter_values.size(); ++i)
    if (m.counter_values[i] < 0)
      return {"bad_value", "counter " + m.counter_names[i] + " = " + std::to_string(m.counter_values[i]) +
                               ", expected >= 0"};
  return {};
}

Refusal checkContent(const run_event_t& m) {
  if (Refusal r = checkUtime(m.utime)) return r;
  if (m.event != "start") return {"bad_enum", "event = '" + m.event + "', expected 'start'"};
  return checkFrame(m.first_frame, "first_frame");
}

// ---------------- frame order ----------------

Refusal FrameOrder::accept(int frame) {
  if (Refusal r = checkFrame(frame)) return r;  // callers check content first; kept for direct use
  if (last_ >= 0) {
    if (frame == last_) return {"duplicate_frame", "frame " + std::to_string(frame) + " again"};
    if (frame < last_)
      return {"old_frame", "frame " + std::to_string(frame) + " after frame " + std::to_string(last_)};
    if (frame - last_ > kMaxFrameJump)
      return {"frame_jump", "frame " + std::to_string(frame) + " after frame " + std::to_string(last_) +
                                ", expected at most " + std::to_string(kMaxFrameJump) + " ahead"};
  }
  last_ = frame;
  return {};
}

}  // namespace dlslot
