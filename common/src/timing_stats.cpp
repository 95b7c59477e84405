#include "dlslot/timing_stats.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace dlslot {

double TimingStats::mean() const {
  return samples_.empty() ? 0.0 : std::accumulate(samples_.begin(), samples_.end(), 0.0) / samples_.size();
}

double TimingStats::percentile(double p) const {
  if (samples_.empty()) return 0.0;
  std::vector<double> s = samples_;
  // Nearest-rank percentile.
  size_t rank = static_cast<size_t>(std::ceil(p / 100.0 * s.size()));
  rank = std::clamp<size_t>(rank, 1, s.size());
  std::nth_element(s.begin(), s.begin() + (rank - 1), s.end());
  return s[rank - 1];
}

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

double TimingStats::max() const {
  return samples_.empty() ? 0.0 : *std::max_element(samples_.begin(), samples_.end());
}

}  // namespace dlslot
