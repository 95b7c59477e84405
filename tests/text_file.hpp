// A file's whole text, for tests that compare outputs or edit a copy of the shipped config.
#pragma once

#include <fstream>
#include <iterator>
#include <string>

namespace dlslot::test {

// The file's bytes ("" when it cannot be read: the caller's comparison then says so).
inline std::string readText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

}  // namespace dlslot::test
