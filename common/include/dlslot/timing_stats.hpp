// Mean / p95 / max of per-frame processing times, and a sample's median.
#pragma once

#include <cstddef>
#include <vector>

namespace dlslot {

class TimingStats {
 public:
  void add(double ms) { samples_.push_back(ms); }
  size_t count() const { return samples_.size(); }
  double mean() const;
  double percentile(double p) const;  // p in [0, 100]; 0 when empty
  double max() const;
  const std::vector<double>& samples() const { return samples_; }

 private:
  std::vector<double> samples_;
};

// The middle value; the mean of the two middle ones for an even count; 0 when empty.
double median(std::vector<double> values);

}  // namespace dlslot
