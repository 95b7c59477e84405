#include "json_text.hpp"

#include <array>
#include <charconv>
#include <cstring>
#include <cmath>
#include <cstdio>

namespace dlslot::foxglove {

void appendBase64(std::string& out, const void* data, size_t size) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  // Two output characters per lookup (12 bits -> a pair): half the table loads of one per 6 bits,
  // and a scan is megabytes of base64.
  static const std::array<char[2], 4096> kPairs = [] {
    std::array<char[2], 4096> t{};
    for (int v = 0; v < 4096; ++v) t[v][0] = kAlphabet[v >> 6], t[v][1] = kAlphabet[v & 63];
    return t;
  }();
  const auto* p = static_cast<const unsigned char*>(data);
  const size_t start = out.size();
  out.resize(start + 4 * ((size + 2) / 3));
  char* o = &out[start];
  size_t i = 0;
  for (; i + 3 <= size; i += 3, o += 4) {
    const uint32_t v = (uint32_t{p[i]} << 16) | (uint32_t{p[i + 1]} << 8) | p[i + 2];
    std::memcpy(o, kPairs[v >> 12], 2);
    std::memcpy(o + 2, kPairs[v & 0xFFF], 2);
  }
  if (i < size) {
    const uint32_t v = (uint32_t{p[i]} << 16) | (i + 1 < size ? uint32_t{p[i + 1]} << 8 : 0);
    *o++ = kAlphabet[v >> 18];
    *o++ = kAlphabet[(v >> 12) & 63];
    *o++ = i + 1 < size ? kAlphabet[(v >> 6) & 63] : '=';
    *o++ = '=';
  }
}

JsonText& JsonText::value(double v) {
  sep();
  if (!std::isfinite(v)) {
    s_ += "null";
    return *this;
  }
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  s_.append(buf, r.ptr);
  return *this;
}

JsonText& JsonText::value(int64_t v) {
  sep();
  char buf[24];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  s_.append(buf, r.ptr);
  return *this;
}

void JsonText::quoted(std::string_view v) {
  s_ += '"';
  for (const char c : v) {
    switch (c) {
      case '"': s_ += "\\\""; break;
      case '\\': s_ += "\\\\"; break;
      case '\n': s_ += "\\n"; break;
      case '\r': s_ += "\\r"; break;
      case '\t': s_ += "\\t"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", c);
          s_ += buf;
        } else {
          s_ += c;
        }
    }
  }
  s_ += '"';
}

}  // namespace dlslot::foxglove
