#include "foxglove_schemas.hpp"

#include "ros1_point_cloud.hpp"

namespace dlslot::foxglove {
namespace {

// Shared pieces of the schemas, as JSON Schema fragments.
const std::string kTime =
    R"({"type":"object","title":"time","properties":{"sec":{"type":"integer","minimum":0},"nsec":{"type":"integer","minimum":0,"maximum":999999999}}})";
const std::string kVector3 =
    R"({"type":"object","title":"foxglove.Vector3","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"}}})";
const std::string kQuaternion =
    R"({"type":"object","title":"foxglove.Quaternion","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"},"w":{"type":"number"}}})";
const std::string kPose = R"({"type":"object","title":"foxglove.Pose","properties":{"position":)" + kVector3 +
                          R"(,"orientation":)" + kQuaternion + "}}";
const std::string kColor =
    R"({"type":"object","title":"foxglove.Color","properties":{"r":{"type":"number"},"g":{"type":"number"},"b":{"type":"number"},"a":{"type":"number"}}})";
const std::string kKeyValue =
    R"({"type":"object","title":"foxglove.KeyValuePair","properties":{"key":{"type":"string"},"value":{"type":"string"}}})";

std::string schema(const char* name, const std::string& properties) {
  return std::string(R"({"$schema":"https://json-schema.org/draft/2020-12/schema","title":")") + name +
         R"(","type":"object","properties":{)" + properties + "}}";
}

std::string array(const std::string& items) { return R"({"type":"array","items":)" + items + "}"; }

}  // namespace

const SchemaText& pointCloudSchema() {
  static const SchemaText s{
      "foxglove.PointCloud",
      schema("foxglove.PointCloud",
             R"("timestamp":)" + kTime + R"(,"frame_id":{"type":"string"},"pose":)" + kPose +
                 R"(,"point_stride":{"type":"integer","minimum":0},"fields":)" +
                 array(R"({"type":"object","title":"foxglove.PackedElementField","properties":{"name":{"type":"string"},"offset":{"type":"integer","minimum":0},"type":{"type":"integer","description":"foxglove.NumericType: 1 UINT8 2 INT8 3 UINT16 4 INT16 5 UINT32 6 INT32 7 FLOAT32 8 FLOAT64"}}})") +
                 R"(,"data":{"type":"string","contentEncoding":"base64"})")};
  return s;
}

const SchemaText& pointCloud2Schema() {
  static const SchemaText s{ros1::kPointCloud2, ros1::pointCloud2Definition(), "ros1msg", "ros1"};
  return s;
}

const SchemaText& sceneUpdateSchema() {
  static const std::string cube = R"({"type":"object","title":"foxglove.CubePrimitive","properties":{"pose":)" +
                                  kPose + R"(,"size":)" + kVector3 + R"(,"color":)" + kColor + "}}";
  static const std::string line =
      R"({"type":"object","title":"foxglove.LinePrimitive","properties":{"type":{"type":"integer","description":"0 LINE_STRIP 1 LINE_LOOP 2 LINE_LIST"},"pose":)" +
      kPose + R"(,"thickness":{"type":"number"},"scale_invariant":{"type":"boolean"},"points":)" + array(kVector3) +
      R"(,"color":)" + kColor + R"(,"colors":)" + array(kColor) + R"(,"indices":{"type":"array","items":{"type":"integer"}}}})";
  static const std::string text =
      R"({"type":"object","title":"foxglove.TextPrimitive","properties":{"pose":)" + kPose +
      R"(,"billboard":{"type":"boolean"},"font_size":{"type":"number"},"scale_invariant":{"type":"boolean"},"color":)" +
      kColor + R"(,"text":{"type":"string"}}})";
  static const std::string empty_list = R"({"type":"array","items":{"type":"object"}})";
  static const std::string entity =
      R"({"type":"object","title":"foxglove.SceneEntity","properties":{"timestamp":)" + kTime +
      R"(,"frame_id":{"type":"string"},"id":{"type":"string"},"lifetime":)" + kTime +
      R"(,"frame_locked":{"type":"boolean"},"metadata":)" + array(kKeyValue) + R"(,"arrows":)" + empty_list +
      R"(,"cubes":)" + array(cube) + R"(,"spheres":)" + empty_list + R"(,"cylinders":)" + empty_list +
      R"(,"lines":)" + array(line) + R"(,"triangles":)" + empty_list + R"(,"texts":)" + array(text) +
      R"(,"models":)" + empty_list + "}}";
  static const SchemaText s{
      "foxglove.SceneUpdate",
      schema("foxglove.SceneUpdate",
             R"("deletions":)" +
                 array(R"({"type":"object","title":"foxglove.SceneEntityDeletion","properties":{"timestamp":)" + kTime +
                       R"(,"type":{"type":"integer","description":"0 MATCHING_ID 1 ALL"},"id":{"type":"string"}}})") +
                 R"(,"entities":)" + array(entity))};
  return s;
}

const SchemaText& frameTransformSchema() {
  static const SchemaText s{"foxglove.FrameTransform",
                            schema("foxglove.FrameTransform",
                                   R"("timestamp":)" + kTime +
                                       R"(,"parent_frame_id":{"type":"string"},"child_frame_id":{"type":"string"},"translation":)" +
                                       kVector3 + R"(,"rotation":)" + kQuaternion)};
  return s;
}

const SchemaText& posesInFrameSchema() {
  static const SchemaText s{"foxglove.PosesInFrame",
                            schema("foxglove.PosesInFrame", R"("timestamp":)" + kTime +
                                                                R"(,"frame_id":{"type":"string"},"poses":)" + array(kPose))};
  return s;
}

const SchemaText& processStatusSchema() {
  static const SchemaText s{
      "dlslot.ProcessStatus",
      schema("dlslot.ProcessStatus",
             R"("timestamp":)" + kTime +
                 R"(,"name":{"type":"string"},"pid":{"type":"integer"},"frames_handled":{"type":"integer"},"last_frame":{"type":"integer"},)"
                 R"("time_mean_ms":{"type":"number"},"time_p95_ms":{"type":"number"},"time_max_ms":{"type":"number"},)"
                 R"("decode_errors":{"type":"integer"},"frame_gaps":{"type":"integer"},"timeouts":{"type":"integer"},"errors":{"type":"integer"},)"
                 R"("last_warning":{"type":"string"},"counters":{"type":"object","additionalProperties":{"type":"integer"}})")};
  return s;
}

const SchemaText& lcmMessageSchema() {
  static const SchemaText s{
      "dlslot.LcmMessage",
      schema("dlslot.LcmMessage",
             R"("channel":{"type":"string"},"fingerprint":{"type":"string","description":"the LCM type hash, 16 hex digits"},)"
             R"("size":{"type":"integer"},"data":{"type":"string","contentEncoding":"base64"})")};
  return s;
}

}  // namespace dlslot::foxglove
