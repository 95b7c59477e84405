// The JSON Schemas of the messages a run becomes: Foxglove's well-known schemas (by name; the
// JSON Schema text describes the fields these messages use, so JSON-aware tools can type them)
// and two of DL-SLOT's own (process status, a message of a channel without a converter); and
// ROS 1's PointCloud2, the live bridge's binary encoding of a scan.
#pragma once

#include <string>

namespace dlslot::foxglove {

struct SchemaText {
  const char* name;  // e.g. "foxglove.PointCloud": Foxglove picks its panels by this name
  std::string text;  // JSON Schema (draft 2020-12) text, or a ROS 1 message definition
  const char* schema_encoding = "jsonschema";  // MCAP / WebSocket names: "jsonschema" or "ros1msg"
  const char* message_encoding = "json";       // how its messages are encoded: "json" or "ros1"
};

const SchemaText& pointCloudSchema();
const SchemaText& pointCloud2Schema();  // sensor_msgs/PointCloud2, ROS 1 encoded (ros1_point_cloud.hpp)
const SchemaText& sceneUpdateSchema();
const SchemaText& frameTransformSchema();
const SchemaText& posesInFrameSchema();
const SchemaText& processStatusSchema();
const SchemaText& lcmMessageSchema();

}  // namespace dlslot::foxglove
