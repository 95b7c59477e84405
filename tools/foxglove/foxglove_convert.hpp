// DL-SLOT's LCM messages as Foxglove messages (JSON encoding; the scan optionally as ROS 1
// PointCloud2, ros1_point_cloud.hpp), one place for the exporter (dlslot-export --mcap) and the
// live bridge (dlslot-foxglove).
//
// Each channel becomes one or more topics, each getting exactly one message per LCM message,
// so every topic's message count equals its channel's count in the log:
//   LIDAR_SCAN     -> /lidar/points          foxglove.PointCloud    (frame lidar; or sensor_msgs/PointCloud2)
//   DETECTIONS     -> /detections            foxglove.SceneUpdate   (lidar; cube + class/score text, coloured by class)
//   GROUND_TRUTH   -> /ground_truth/boxes    foxglove.SceneUpdate   (lidar; coloured by id)
//                     /ground_truth/path     foxglove.PosesInFrame  (world; the poses so far)
//   ODOMETRY       -> /odometry/path         foxglove.PosesInFrame  (world)
//   ASSOCIATIONS   -> /tracker/associations  foxglove.SceneUpdate   (world; coloured by track id)
//   SLOT_STATE     -> /tf                    foxglove.FrameTransform world -> lidar (DL-SLOT's ego pose)
//                     /slot/path             foxglove.PosesInFrame  (world)
//                     /slot/tracks           foxglove.SceneUpdate   (world; cube, "id class speed" text,
//                                                                    the track's recent path as a line)
//   MAP_STATE      -> /map/tf                foxglove.FrameTransform map -> world (the loop closure's correction)
//                     /map/path              foxglove.PosesInFrame  (map; the loop-closed pose of each scan as it came)
//                     /map/loops             foxglove.SceneUpdate   (map; a line for every accepted loop so far)
//   PROCESS_STATUS -> /process_status        dlslot.ProcessStatus
//   any other      -> /lcm/CHANNEL           dlslot.LcmMessage (the raw bytes, base64)
// Frames: "world" is the lidar frame of the first scan (design brief, section 3); "lidar" moves
// with the vehicle, placed by /tf at each scan's timestamp; "map" is the mapper's loop-closed world
// (identical to "world" until a loop closes).
#pragma once

#include <cstdint>
#include <array>
#include <deque>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "dlslot/associations_t.hpp"
#include "dlslot/config.hpp"
#include "dlslot/detections_t.hpp"
#include "dlslot/ground_truth_t.hpp"
#include "dlslot/map_state_t.hpp"
#include "dlslot/message_guard.hpp"
#include "dlslot/odometry_t.hpp"
#include "dlslot/point_cloud_t.hpp"
#include "dlslot/process_status_t.hpp"
#include "dlslot/slot_state_t.hpp"
#include "foxglove_schemas.hpp"
#include "json_text.hpp"

namespace dlslot::foxglove {

inline constexpr const char* kWorldFrame = "world";
inline constexpr const char* kLidarFrame = "lidar";
// The mapper's loop-closed world; /map/tf places SLOT_STATE's world in it (T_map_world).
inline constexpr const char* kMapFrame = "map";

struct Topic {
  std::string name;          // e.g. "/lidar/points"
  const SchemaText* schema;  // never null
  std::string channel;       // the LCM channel it comes from
};

// One Foxglove message: the topic (index into Converter::topics()), its bytes in the topic's
// schema's message encoding (JSON text, or ROS 1 serialized) and the timestamp of the scan it
// belongs to (microseconds; -1 for messages of no scan: status, raw).
struct Output {
  size_t topic;
  std::string bytes;
  int64_t utime;
};

// How /lidar/points is encoded. JSON (foxglove.PointCloud, points in base64) keeps every topic
// of an MCAP file readable as JSON; ROS 1 PointCloud2 is a quarter smaller and costs a copy of the
// points instead of a base64 pass, which the live bridge needs to keep pace with the pipeline.
enum class ScanEncoding { kJson, kRos1 };

struct ConverterOptions {
  ScanEncoding scan_encoding = ScanEncoding::kJson;
  // A track's recent path drawn behind it: 3 s at KITTI's 10 Hz shows where it is heading
  // without the lines of a long run crowding the scene.
  int track_path_frames = 30;
};

class Converter {
 public:
  // The fixed topics, in this order (indices into topics()).
  enum FixedTopic : size_t {
    kScan, kDetections, kGtBoxes, kGtPath, kOdomPath, kAssociations, kTf, kSlotPath, kTracks,
    kMapTf, kMapPath, kMapLoops, kStatus, kNumFixed
  };

  explicit Converter(const Channels& channels = Channels(), ConverterOptions options = {});

  // Fixed topics first, then one per channel without a converter, in order of first sight.
  const std::vector<Topic>& topics() const { return topics_; }
  // Topics whose JSON to build (the bridge: those a client subscribed to); all by default. State
  // (trajectories, track paths) is kept whatever is wanted.
  void setWanted(std::function<bool(size_t topic)> wanted) { wanted_ = std::move(wanted); }

  // Decodes `data` as the type of `channel` through the message guard and converts it. Returns
  // the refusal (nothing appended) when it does not decode or is not valid; a channel of no
  // known type is passed through as dlslot.LcmMessage.
  Refusal convert(const std::string& channel, const void* data, size_t size, std::vector<Output>& out);
  // A scan from its LCM bytes, checked as the guard checks it (refused: nothing appended). In
  // ROS 1 encoding the points go from the LCM bytes to the PointCloud2 in one pass (no decoded
  // message in between), and a scan no one wants is only checked up to its points. `frame` (when
  // given) gets the scan's frame.
  Refusal addScan(const void* data, size_t size, std::vector<Output>& out, int* frame = nullptr);
  // The typed entry points (the bridge's typed subscriptions call these).
  void add(const point_cloud_t& m, std::vector<Output>& out);
  void add(const detections_t& m, std::vector<Output>& out);
  void add(const ground_truth_t& m, std::vector<Output>& out);
  void add(const odometry_t& m, std::vector<Output>& out);
  void add(const associations_t& m, std::vector<Output>& out);
  void add(const slot_state_t& m, std::vector<Output>& out);
  void add(const map_state_t& m, std::vector<Output>& out);
  void add(const process_status_t& m, std::vector<Output>& out);
  void addRaw(const std::string& channel, const void* data, size_t size, std::vector<Output>& out);

  const Channels& channels() const { return channels_; }

 private:
  bool wanted(size_t topic) const { return !wanted_ || wanted_(topic); }
  void posesInFrame(int64_t utime, const std::vector<pose_t>& poses, const char* frame = kWorldFrame);
  // A foxglove.FrameTransform: the pose of `child` in `parent`.
  void frameTransform(int64_t utime, const char* parent, const char* child, const pose_t& child_in_parent);
  void boxEntity(int64_t utime, const char* frame, const std::string& id, const box_t& b, const float rgba[4],
                 const std::string& label, const std::vector<std::pair<const char*, std::string>>& metadata,
                 const std::deque<std::array<double, 3>>* path = nullptr);
  void beginSceneUpdate(int64_t utime);
  void endSceneUpdate();

  Channels channels_;
  ConverterOptions opt_;
  std::vector<Topic> topics_;
  std::map<std::string, size_t> raw_topics_;  // channel -> topic index
  std::function<bool(size_t)> wanted_;
  std::vector<pose_t> gt_path_, odom_path_, slot_path_, map_path_;
  std::map<int, std::array<double, 3>> map_positions_;  // frame -> its loop-closed position when it came
  std::vector<std::pair<int, int>> loops_;             // accepted loops: (match frame, query frame)
  std::map<int, std::deque<std::array<double, 3>>> track_paths_;  // id -> recent world positions
  JsonText j_;
};

// Colours: by class for detections (one hue per KITTI class family), by id for tracks (golden
// ratio hue steps, so neighbouring ids differ).
void classColour(const std::string& type, float rgba[4]);
void idColour(int id, float rgba[4]);

}  // namespace dlslot::foxglove
