#include "dlslot/scan_encoding.hpp"

#include <cstring>

#include "dlslot/point_cloud_t.hpp"

namespace dlslot {
namespace {

// LCM's wire format is big-endian.
inline uint8_t* put32(uint8_t* p, uint32_t v) {
  v = __builtin_bswap32(v);
  std::memcpy(p, &v, 4);
  return p + 4;
}

inline uint8_t* put64(uint8_t* p, uint64_t v) {
  v = __builtin_bswap64(v);
  std::memcpy(p, &v, 8);
  return p + 8;
}

}  // namespace

void encodeScan(const PointCloud& scan, int64_t utime, int32_t frame, const std::string& sequence,
                std::vector<uint8_t>& out) {
  const size_t n = static_cast<size_t>(scan.cols());
  // lcm-gen writes a string up to its first NUL, then the NUL; its length counts the NUL.
  const size_t seq_len = std::strlen(sequence.c_str());
  const size_t size = 8 + 8 + 4 + 4 + seq_len + 1 + 4 + 16 * n;
  out.resize(size);
  uint8_t* p = out.data();
  p = put64(p, static_cast<uint64_t>(point_cloud_t::getHash()));
  p = put64(p, static_cast<uint64_t>(utime));
  p = put32(p, static_cast<uint32_t>(frame));
  p = put32(p, static_cast<uint32_t>(seq_len + 1));
  std::memcpy(p, sequence.c_str(), seq_len + 1);
  p += seq_len + 1;
  p = put32(p, static_cast<uint32_t>(n));
  // x[n], y[n], z[n], intensity[n]: the scan's rows (it is column-major, 4 floats a point).
  const float* src = scan.data();
  for (int row = 0; row < 4; ++row) {
    for (size_t i = 0; i < n; ++i) {
      uint32_t v;
      std::memcpy(&v, src + 4 * i + row, 4);
      put32(p + 4 * i, v);
    }
    p += 4 * n;
  }
}

}  // namespace dlslot
