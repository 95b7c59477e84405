// One error type for bad input files, so every reader names the file, the line and what it expected.
#pragma once

#include <stdexcept>
#include <string>

namespace dlslot {

class InputError : public std::runtime_error {
 public:
  // "FILE:LINE: WHAT" (line 0 = the file as a whole).
  InputError(const std::string& file, int line, const std::string& what)
      : std::runtime_error(file + (line > 0 ? ":" + std::to_string(line) : std::string()) + ": " + what) {}
};

}  // namespace dlslot
