// The JSON Schemas of the messages a run becomes: Foxglove's well-known schemas (by name; the
// JSON Schema text describes the fields these messages use, so JSON-aware tools can type them)
// and two of DL-SLOT's own (process status, a message of a channel without a converter).
#pragma once

#include <string>

namespace dlslot::foxglove {

struct SchemaText {
  const char* name;  // e.g. "foxglove.PointCloud": Foxglove picks its panels by this name
  std::string json;  // JSON Schema (draft 2020-12) text
};

const SchemaText& pointCloudSchema();
const SchemaText& sceneUpdateSchema();
const SchemaText& frameTransformSchema();
const SchemaText& posesInFrameSchema();
const SchemaText& processStatusSchema();
const SchemaText& lcmMessageSchema();

}  // namespace dlslot::foxglove
