// Writing JSON text fast: Foxglove's JSON message encoding carries a point cloud as base64 in a
// JSON string, 2-3 MB a scan, so the text is appended into one reused buffer with no DOM.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace dlslot::foxglove {

// Standard base64 (RFC 4648, with padding): how JSON carries Foxglove's `bytes` fields.
void appendBase64(std::string& out, const void* data, size_t size);

// Appends JSON tokens; the caller keeps the structure (objects, arrays) balanced.
class JsonText {
 public:
  std::string& str() { return s_; }
  void clear() { s_.clear(); first_ = true; }
  JsonText& beginObject() { sep(); s_ += '{'; first_ = true; return *this; }
  JsonText& endObject() { s_ += '}'; first_ = false; return *this; }
  JsonText& beginArray() { sep(); s_ += '['; first_ = true; return *this; }
  JsonText& endArray() { s_ += ']'; first_ = false; return *this; }
  // An object key; the value follows with one of the value calls.
  JsonText& key(std::string_view k) { sep(); quoted(k); s_ += ':'; first_ = true; return *this; }
  JsonText& value(std::string_view v) { sep(); quoted(v); return *this; }
  JsonText& value(const char* v) { return value(std::string_view(v)); }
  JsonText& value(const std::string& v) { return value(std::string_view(v)); }
  JsonText& value(double v);                 // shortest round-trip form; NaN/inf as null
  JsonText& value(int64_t v);
  JsonText& value(int v) { return value(static_cast<int64_t>(v)); }
  JsonText& value(bool v) { sep(); s_ += v ? "true" : "false"; return *this; }
  JsonText& null() { sep(); s_ += "null"; return *this; }
  JsonText& base64(const void* data, size_t size) { sep(); s_ += '"'; appendBase64(s_, data, size); s_ += '"'; return *this; }
  // key + value in one call.
  template <class T>
  JsonText& field(std::string_view k, const T& v) { key(k); return value(v); }

 private:
  void sep() {
    if (!first_) s_ += ',';
    first_ = false;
  }
  void quoted(std::string_view v);
  std::string s_;
  bool first_ = true;
};

}  // namespace dlslot::foxglove
