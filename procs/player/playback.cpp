#include "playback.hpp"

#include <stdexcept>

namespace dlslot::player {

FrameRange resolveRange(FrameRange r, int num_frames) {
  if (r.end < 0) r.end = num_frames - 1;
  if (r.start < 0 || r.start >= num_frames)
    throw std::invalid_argument("--start " + std::to_string(r.start) + ": expected a frame in 0.." +
                                std::to_string(num_frames - 1));
  if (r.end >= num_frames)
    throw std::invalid_argument("--end " + std::to_string(r.end) + ": expected a frame in 0.." +
                                std::to_string(num_frames - 1));
  if (r.end < r.start)
    throw std::invalid_argument("--end " + std::to_string(r.end) + " is before --start " + std::to_string(r.start));
  return r;
}

}  // namespace dlslot::player
