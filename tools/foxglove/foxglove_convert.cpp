#include "foxglove_convert.hpp"

#include "palette.hpp"  // procs/renderer: the same track colours as the bird's-eye images

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <set>

#include "ros1_point_cloud.hpp"

namespace dlslot::foxglove {
namespace {

void time(JsonText& j, int64_t utime) {
  const int64_t us = utime < 0 ? 0 : utime;
  j.beginObject().field("sec", us / 1000000).field("nsec", (us % 1000000) * 1000).endObject();
}

void vec3(JsonText& j, double x, double y, double z) {
  j.beginObject().field("x", x).field("y", y).field("z", z).endObject();
}

// pose_t keeps the quaternion as (w, x, y, z); Foxglove names the parts.
void quat(JsonText& j, const double q[4]) {
  j.beginObject().field("x", q[1]).field("y", q[2]).field("z", q[3]).field("w", q[0]).endObject();
}

void pose(JsonText& j, const pose_t& p) {
  j.beginObject().key("position");
  vec3(j, p.position[0], p.position[1], p.position[2]);
  j.key("orientation");
  quat(j, p.orientation);
  j.endObject();
}

void poseYaw(JsonText& j, double x, double y, double z, double yaw) {
  const double q[4] = {std::cos(yaw / 2), 0, 0, std::sin(yaw / 2)};
  j.beginObject().key("position");
  vec3(j, x, y, z);
  j.key("orientation");
  quat(j, q);
  j.endObject();
}

void colour(JsonText& j, const float c[4]) {
  j.beginObject().field("r", double(c[0])).field("g", double(c[1])).field("b", double(c[2])).field("a", double(c[3])).endObject();
}

std::string fixed(double v, int decimals) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

// The standard deviation of a track's speed: its velocity covariance along its velocity; 0 when
// it gave none (a still track, or covariances not computed).
double speedSigma(const track_t& t) {
  const double speed = std::hypot(t.velocity[0], t.velocity[1], t.velocity[2]);
  if (speed <= 0) return 0;
  double var = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) var += t.velocity[i] * t.velocity_covariance[3 * i + j] * t.velocity[j];
  return std::sqrt(std::max(0.0, var)) / speed;
}

}  // namespace

void classColour(const std::string& type, float rgba[4]) {
  // Vehicles blue, people red, cyclists yellow, the rest grey; translucent so the points inside show.
  rgba[3] = 0.45f;
  if (type == "Car" || type == "Van" || type == "Truck" || type == "Tram")
    rgba[0] = 0.2f, rgba[1] = 0.55f, rgba[2] = 1.0f;
  else if (type == "Pedestrian" || type == "Person_sitting")
    rgba[0] = 1.0f, rgba[1] = 0.3f, rgba[2] = 0.3f;
  else if (type == "Cyclist")
    rgba[0] = 1.0f, rgba[1] = 0.85f, rgba[2] = 0.2f;
  else
    rgba[0] = rgba[1] = rgba[2] = 0.7f;
}

void idColour(int id, float rgba[4]) {
  // The renderer's colour of the track, so a track looks the same in Foxglove and in bev/.
  const cv::Scalar bgr = renderer::trackColour(id);
  rgba[0] = float(bgr[2] / 255.0), rgba[1] = float(bgr[1] / 255.0), rgba[2] = float(bgr[0] / 255.0);
  rgba[3] = 0.55f;
}

Converter::Converter(const Channels& channels, ConverterOptions options) : channels_(channels), opt_(options) {
  topics_ = {
      {"/lidar/points", opt_.scan_encoding == ScanEncoding::kRos1 ? &pointCloud2Schema() : &pointCloudSchema(),
       channels_.scan},
      {"/detections", &sceneUpdateSchema(), channels_.detections},
      {"/ground_truth/boxes", &sceneUpdateSchema(), channels_.ground_truth},
      {"/ground_truth/path", &posesInFrameSchema(), channels_.ground_truth},
      {"/odometry/path", &posesInFrameSchema(), channels_.odometry},
      {"/tracker/associations", &sceneUpdateSchema(), channels_.associations},
      {"/tf", &frameTransformSchema(), channels_.slot_state},
      {"/slot/path", &posesInFrameSchema(), channels_.slot_state},
      {"/slot/tracks", &sceneUpdateSchema(), channels_.slot_state},
      {"/map/tf", &frameTransformSchema(), channels_.map_state},
      {"/map/path", &posesInFrameSchema(), channels_.map_state},
      {"/map/loops", &sceneUpdateSchema(), channels_.map_state},
      {"/process_status", &processStatusSchema(), channels_.status},
  };
}

Refusal Converter::convert(const std::string& channel, const void* data, size_t size, std::vector<Output>& out) {
  auto as = [&](auto msg) -> Refusal {
    if (Refusal r = decodeChecked(data, size, &msg)) return r;
    add(msg, out);
    return {};
  };
  if (channel == channels_.scan) return addScan(data, size, out);
  if (channel == channels_.detections) return as(detections_t());
  if (channel == channels_.ground_truth) return as(ground_truth_t());
  if (channel == channels_.odometry) return as(odometry_t());
  if (channel == channels_.associations) return as(associations_t());
  if (channel == channels_.slot_state) return as(slot_state_t());
  if (channel == channels_.map_state) return as(map_state_t());
  if (channel == channels_.status) return as(process_status_t());
  addRaw(channel, data, size, out);
  return {};
}

Refusal Converter::addScan(const void* data, size_t size, std::vector<Output>& out, int* frame) {
  if (opt_.scan_encoding == ScanEncoding::kJson) {
    point_cloud_t m;
    if (Refusal r = decodeChecked(data, size, &m)) return r;
    if (frame) *frame = m.frame;
    add(m, out);
    return {};
  }
  ros1::ScanId id;
  if (!wanted(kScan)) {
    const Refusal r = ros1::checkScanHeader(data, size, &id);
    if (!r && frame) *frame = id.frame;
    return r;
  }
  Output o{kScan, {}, -1};
  if (Refusal r = ros1::writePointCloud2FromLcm(data, size, kLidarFrame, o.bytes, &id)) return r;
  if (frame) *frame = id.frame;
  o.utime = id.utime;
  out.push_back(std::move(o));
  return {};
}

void Converter::add(const point_cloud_t& m, std::vector<Output>& out) {
  if (!wanted(kScan)) return;
  if (opt_.scan_encoding == ScanEncoding::kRos1) {
    out.push_back({kScan, {}, m.utime});
    ros1::writePointCloud2(m, kLidarFrame, out.back().bytes);
    return;
  }
  // Interleaved little-endian float32 x y z intensity, 16 bytes a point (x86 is little-endian,
  // as Foxglove's packed fields are).
  static_assert(sizeof(float) == 4, "float32");
  std::vector<float> packed(4 * static_cast<size_t>(m.num_points));
  for (int i = 0; i < m.num_points; ++i) {
    float* p = &packed[4 * static_cast<size_t>(i)];
    p[0] = m.x[i], p[1] = m.y[i], p[2] = m.z[i], p[3] = m.intensity[i];
  }
  j_.clear();
  j_.str().reserve(packed.size() * sizeof(float) * 4 / 3 + 512);  // the base64 dominates
  j_.beginObject().key("timestamp");
  time(j_, m.utime);
  j_.field("frame_id", kLidarFrame).key("pose");
  poseYaw(j_, 0, 0, 0, 0);
  j_.field("point_stride", 16).key("fields").beginArray();
  const char* names[4] = {"x", "y", "z", "intensity"};
  for (int f = 0; f < 4; ++f) j_.beginObject().field("name", names[f]).field("offset", 4 * f).field("type", 7).endObject();
  j_.endArray().key("data").base64(packed.data(), packed.size() * sizeof(float)).endObject();
  out.push_back({kScan, std::move(j_.str()), m.utime});
}

void Converter::beginSceneUpdate(int64_t utime) {
  j_.clear();
  // Each update replaces the topic's previous boxes: delete all entities stamped up to now.
  j_.beginObject().key("deletions").beginArray().beginObject().key("timestamp");
  time(j_, utime);
  j_.field("type", 1).field("id", "").endObject().endArray().key("entities").beginArray();
}

void Converter::endSceneUpdate() { j_.endArray().endObject(); }

void Converter::boxEntity(int64_t utime, const char* frame, const std::string& id, const box_t& b, const float rgba[4],
                          const std::string& label,
                          const std::vector<std::pair<const char*, std::string>>& metadata,
                          const std::deque<std::array<double, 3>>* path) {
  j_.beginObject().key("timestamp");
  time(j_, utime);
  j_.field("frame_id", frame).field("id", id).key("lifetime");
  time(j_, 0);
  j_.field("frame_locked", false).key("metadata").beginArray();
  for (const auto& [k, v] : metadata) j_.beginObject().field("key", k).field("value", v).endObject();
  j_.endArray();
  j_.key("arrows").beginArray().endArray();
  j_.key("cubes").beginArray().beginObject().key("pose");
  poseYaw(j_, b.center[0], b.center[1], b.center[2], b.yaw);
  j_.key("size");
  vec3(j_, b.size[0], b.size[1], b.size[2]);
  j_.key("color");
  colour(j_, rgba);
  j_.endObject().endArray();
  j_.key("spheres").beginArray().endArray().key("cylinders").beginArray().endArray();
  j_.key("lines").beginArray();
  if (path && path->size() >= 2) {
    const float line_rgba[4] = {rgba[0], rgba[1], rgba[2], 1.0f};
    j_.beginObject().field("type", 0).key("pose");
    poseYaw(j_, 0, 0, 0, 0);
    j_.field("thickness", 0.15).field("scale_invariant", false).key("points").beginArray();
    for (const auto& p : *path) vec3(j_, p[0], p[1], p[2]);
    j_.endArray().key("color");
    colour(j_, line_rgba);
    j_.key("colors").beginArray().endArray().key("indices").beginArray().endArray().endObject();
  }
  j_.endArray().key("triangles").beginArray().endArray();
  j_.key("texts").beginArray().beginObject().key("pose");
  poseYaw(j_, b.center[0], b.center[1], b.center[2] + b.size[2] / 2 + 0.5, 0);
  const float white[4] = {1, 1, 1, 1};
  j_.field("billboard", true).field("font_size", 14.0).field("scale_invariant", true).key("color");
  colour(j_, white);
  j_.field("text", label).endObject().endArray();
  j_.key("models").beginArray().endArray().endObject();
}

void Converter::add(const detections_t& m, std::vector<Output>& out) {
  if (!wanted(kDetections)) return;
  beginSceneUpdate(m.utime);
  float c[4];
  for (int i = 0; i < m.num_boxes; ++i) {
    const box_t& b = m.boxes[i];
    classColour(b.type, c);
    boxEntity(m.utime, kLidarFrame, "detection/" + std::to_string(i), b, c, b.type + " " + fixed(b.score, 2),
              {{"class", b.type}, {"score", fixed(b.score, 3)}, {"source", m.source}});
  }
  endSceneUpdate();
  out.push_back({kDetections, std::move(j_.str()), m.utime});
}

void Converter::add(const ground_truth_t& m, std::vector<Output>& out) {
  if (m.has_pose) gt_path_.push_back(m.pose);
  if (wanted(kGtBoxes)) {
    beginSceneUpdate(m.utime);
    float c[4];
    for (int i = 0; i < m.num_boxes; ++i) {
      const box_t& b = m.boxes[i];
      idColour(b.id, c);
      boxEntity(m.utime, kLidarFrame, "truth/" + std::to_string(b.id) + "/" + std::to_string(i), b, c,
                "truth " + std::to_string(b.id) + " " + b.type, {{"id", std::to_string(b.id)}, {"class", b.type}});
    }
    endSceneUpdate();
    out.push_back({kGtBoxes, std::move(j_.str()), m.utime});
  }
  if (wanted(kGtPath)) {
    posesInFrame(m.utime, gt_path_);
    out.push_back({kGtPath, std::move(j_.str()), m.utime});
  }
}

void Converter::frameTransform(int64_t utime, const char* parent, const char* child, const pose_t& child_in_parent) {
  j_.clear();
  j_.beginObject().key("timestamp");
  time(j_, utime);
  j_.field("parent_frame_id", parent).field("child_frame_id", child).key("translation");
  vec3(j_, child_in_parent.position[0], child_in_parent.position[1], child_in_parent.position[2]);
  j_.key("rotation");
  quat(j_, child_in_parent.orientation);
  j_.endObject();
}

void Converter::posesInFrame(int64_t utime, const std::vector<pose_t>& poses, const char* frame) {
  j_.clear();
  j_.beginObject().key("timestamp");
  time(j_, utime);
  j_.field("frame_id", frame).key("poses").beginArray();
  for (const auto& p : poses) pose(j_, p);
  j_.endArray().endObject();
}

void Converter::add(const odometry_t& m, std::vector<Output>& out) {
  odom_path_.push_back(m.pose);
  if (!wanted(kOdomPath)) return;
  posesInFrame(m.utime, odom_path_);
  out.push_back({kOdomPath, std::move(j_.str()), m.utime});
}

void Converter::add(const associations_t& m, std::vector<Output>& out) {
  if (!wanted(kAssociations)) return;
  beginSceneUpdate(m.utime);
  float c[4];
  for (int i = 0; i < m.num_associations; ++i) {
    const association_t& a = m.associations[i];
    idColour(a.track_id, c);
    boxEntity(m.utime, kWorldFrame, "association/" + std::to_string(i), a.box_world, c,
              "id " + std::to_string(a.track_id) + (a.initialized ? "" : " (new)"),
              {{"track_id", std::to_string(a.track_id)},
               {"class", a.box_world.type},
               {"initialized", a.initialized ? "true" : "false"},
               {"observations", std::to_string(a.num_observations)}});
  }
  endSceneUpdate();
  out.push_back({kAssociations, std::move(j_.str()), m.utime});
}

void Converter::add(const slot_state_t& m, std::vector<Output>& out) {
  slot_path_.push_back(m.ego_pose);
  // Recent paths of the tracks of this state; those no longer tracked are forgotten.
  std::set<int> present;
  for (int i = 0; i < m.num_tracks; ++i) {
    const track_t& t = m.tracks[i];
    present.insert(t.id);
    auto& path = track_paths_[t.id];
    path.push_back({t.pose.position[0], t.pose.position[1], t.pose.position[2]});
    while (static_cast<int>(path.size()) > opt_.track_path_frames) path.pop_front();
  }
  for (auto it = track_paths_.begin(); it != track_paths_.end();)
    it = present.count(it->first) ? std::next(it) : track_paths_.erase(it);

  if (wanted(kTf)) {
    frameTransform(m.utime, kWorldFrame, kLidarFrame, m.ego_pose);
    out.push_back({kTf, std::move(j_.str()), m.utime});
  }
  if (wanted(kSlotPath)) {
    posesInFrame(m.utime, slot_path_);
    out.push_back({kSlotPath, std::move(j_.str()), m.utime});
  }
  if (wanted(kTracks)) {
    beginSceneUpdate(m.utime);
    float c[4];
    for (int i = 0; i < m.num_tracks; ++i) {
      const track_t& t = m.tracks[i];
      box_t b;
      b.type = t.type;
      b.id = t.id;
      for (int k = 0; k < 3; ++k) b.center[k] = t.pose.position[k], b.size[k] = t.size[k];
      const double* q = t.pose.orientation;  // w x y z: heading of the box's x axis
      b.yaw = std::atan2(2 * (q[0] * q[3] + q[1] * q[2]), 1 - 2 * (q[2] * q[2] + q[3] * q[3]));
      const double speed = std::hypot(t.velocity[0], t.velocity[1], t.velocity[2]);
      const double sigma = speedSigma(t);
      idColour(t.id, c);
      const char* status = t.status == track_t::STATUS_CONFIRMED ? "confirmed"
                           : t.status == track_t::STATUS_COASTING ? "coasting" : "tentative";
      boxEntity(m.utime, kWorldFrame, "track/" + std::to_string(t.id), b, c,
                std::to_string(t.id) + " " + t.type + " " + fixed(speed, 1) + (sigma > 0 ? "±" + fixed(sigma, 1) : "") +
                    " m/s" + (t.is_dynamic ? "" : " static"),
                {{"id", std::to_string(t.id)},
                 {"class", t.type},
                 {"speed_mps", fixed(speed, 2)},
                 {"speed_sigma_mps", fixed(sigma, 2)},
                 {"dynamic", t.is_dynamic ? "true" : "false"},
                 {"status", status},
                 {"confidence", fixed(t.confidence, 3)}},
                &track_paths_[t.id]);
    }
    endSceneUpdate();
    out.push_back({kTracks, std::move(j_.str()), m.utime});
  }
}

void Converter::add(const map_state_t& m, std::vector<Output>& out) {
  map_path_.push_back(m.map_pose);
  map_positions_[m.frame] = {m.map_pose.position[0], m.map_pose.position[1], m.map_pose.position[2]};
  for (const loop_event_t& e : m.loops)
    if (e.accepted) loops_.emplace_back(e.match_frame, e.query_frame);
  if (wanted(kMapTf)) {
    frameTransform(m.utime, kMapFrame, kWorldFrame, m.map_from_world);
    out.push_back({kMapTf, std::move(j_.str()), m.utime});
  }
  if (wanted(kMapPath)) {
    posesInFrame(m.utime, map_path_, kMapFrame);
    out.push_back({kMapPath, std::move(j_.str()), m.utime});
  }
  if (!wanted(kMapLoops)) return;
  // Every accepted loop so far, a red line from the place seen before to the scan that saw it again
  // (each end where the mapper placed it when it came).
  beginSceneUpdate(m.utime);
  const float red[4] = {1.0f, 0.1f, 0.1f, 1.0f}, white[4] = {1, 1, 1, 1};
  for (const auto& [match, query] : loops_) {
    const auto a = map_positions_.find(match), b = map_positions_.find(query);
    if (a == map_positions_.end() || b == map_positions_.end()) continue;
    const auto& p = a->second;
    const auto& q = b->second;
    j_.beginObject().key("timestamp");
    time(j_, m.utime);
    j_.field("frame_id", kMapFrame).field("id", "loop/" + std::to_string(match) + "-" + std::to_string(query));
    j_.key("lifetime");
    time(j_, 0);
    j_.field("frame_locked", false).key("metadata").beginArray();
    j_.beginObject().field("key", "match_frame").field("value", std::to_string(match)).endObject();
    j_.beginObject().field("key", "query_frame").field("value", std::to_string(query)).endObject();
    j_.endArray().key("arrows").beginArray().endArray().key("cubes").beginArray().endArray();
    j_.key("spheres").beginArray().endArray().key("cylinders").beginArray().endArray();
    j_.key("lines").beginArray().beginObject().field("type", 0).key("pose");
    poseYaw(j_, 0, 0, 0, 0);
    j_.field("thickness", 0.4).field("scale_invariant", false).key("points").beginArray();
    vec3(j_, p[0], p[1], p[2]);
    vec3(j_, q[0], q[1], q[2]);
    j_.endArray().key("color");
    colour(j_, red);
    j_.key("colors").beginArray().endArray().key("indices").beginArray().endArray().endObject().endArray();
    j_.key("triangles").beginArray().endArray().key("texts").beginArray().beginObject().key("pose");
    poseYaw(j_, q[0], q[1], q[2] + 2.0, 0);
    j_.field("billboard", true).field("font_size", 14.0).field("scale_invariant", true).key("color");
    colour(j_, white);
    j_.field("text", "loop " + std::to_string(query) + " -> " + std::to_string(match)).endObject().endArray();
    j_.key("models").beginArray().endArray().endObject();
  }
  endSceneUpdate();
  out.push_back({kMapLoops, std::move(j_.str()), m.utime});
}

void Converter::add(const process_status_t& m, std::vector<Output>& out) {
  if (!wanted(kStatus)) return;
  j_.clear();
  j_.beginObject().key("timestamp");
  time(j_, m.utime);
  j_.field("name", m.name).field("pid", int64_t{m.pid}).field("frames_handled", m.frames_handled)
      .field("last_frame", int64_t{m.last_frame}).field("time_mean_ms", m.time_mean_ms).field("time_p95_ms", m.time_p95_ms)
      .field("time_max_ms", m.time_max_ms).field("decode_errors", m.decode_errors).field("frame_gaps", m.frame_gaps)
      .field("timeouts", m.timeouts).field("errors", m.errors).field("last_warning", m.last_warning);
  j_.key("counters").beginObject();
  for (int i = 0; i < m.num_counters; ++i) j_.field(m.counter_names[i], m.counter_values[i]);
  j_.endObject().endObject();
  out.push_back({kStatus, std::move(j_.str()), -1});
}

void Converter::addRaw(const std::string& channel, const void* data, size_t size, std::vector<Output>& out) {
  auto it = raw_topics_.find(channel);
  if (it == raw_topics_.end()) {
    topics_.push_back({"/lcm/" + channel, &lcmMessageSchema(), channel});
    it = raw_topics_.emplace(channel, topics_.size() - 1).first;
  }
  if (!wanted(it->second)) return;
  char hash[17] = "";
  if (size >= 8) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (int i = 0; i < 8; ++i) std::snprintf(hash + 2 * i, 3, "%02x", p[i]);
  }
  j_.clear();
  j_.beginObject().field("channel", channel).field("fingerprint", std::string(hash)).field("size", int64_t(size));
  j_.key("data").base64(data, size).endObject();
  out.push_back({it->second, std::move(j_.str()), -1});
}

}  // namespace dlslot::foxglove
