// The player's LCM-free logic: which frames to play and when. Reading the data set is
// kitti::SequenceReader (common), message conversion is convert.hpp (common).
#pragma once

#include <cstdint>
#include <string>

namespace dlslot::player {

struct FrameRange {
  int start = 0;
  int end = -1;  // inclusive; -1 = last frame
};
// Clamps and checks a requested range against a sequence of `num_frames`; throws
// std::invalid_argument naming the option when it is empty or out of range.
FrameRange resolveRange(FrameRange requested, int num_frames);

// Rate mode: frame times are the data set's timestamps scaled by 1/speed (speed <= 0: as fast
// as possible). Returns the wall-clock offset in seconds from the first played frame.
class RatePacer {
 public:
  RatePacer(int64_t first_utime, double speed) : first_utime_(first_utime), speed_(speed) {}
  double offsetSeconds(int64_t utime) const {
    return speed_ <= 0 ? 0.0 : (utime - first_utime_) * 1e-6 / speed_;
  }

 private:
  int64_t first_utime_;
  double speed_;
};

}  // namespace dlslot::player
