// When a run whose player is done may stop its processes. A process can still hold frames it has
// not taken (under load the mapper's main thread fell five scans behind, still in its socket, as
// the last SLOT_STATE arrived); stopped then, it loses them. So the launcher waits while some
// process has frames to account for and is still taking them; one that has stopped taking them
// (no change in its count over `patience_s`, three heartbeats) is lost as before, and reported.
#pragma once

namespace dlslot::run {

class EndWait {
 public:
  explicit EndWait(double patience_s = 3.0) : patience_s_(patience_s) {}

  // `now_s`: a steady clock in seconds; `missing`: frames the pipeline has not accounted for yet;
  // `taken`: frames handled or skipped, summed over the processes. True: wait and ask again.
  bool waiting(double now_s, long long missing, long long taken) {
    if (missing <= 0) return false;
    if (!started_ || taken != taken_) {  // progress: the patience starts again
      started_ = true;
      taken_ = taken;
      since_s_ = now_s;
    }
    return now_s - since_s_ < patience_s_;
  }

 private:
  double patience_s_;
  bool started_ = false;
  long long taken_ = 0;
  double since_s_ = 0;
};

}  // namespace dlslot::run
