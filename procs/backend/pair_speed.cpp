#include "backend/pair_speed.hpp"

#include <algorithm>
#include <cmath>

#include "dlslot/timing_stats.hpp"

namespace dlslot::backend {

bool countsAlone(const PairSpeed& p, int trusted_points) {
  return p.on_line ? *p.on_line : p.points >= trusted_points;
}

std::optional<VelocityEvidence> medianPairVelocity(const std::vector<PairSpeed>& pairs, int trusted_points) {
  std::vector<double> speeds, sigmas;
  const PairSpeed* newest = nullptr;
  for (const PairSpeed& p : pairs) {
    if (!(p.sigma > 0)) continue;
    const auto agrees = [&](const PairSpeed& q) {
      return &q != &p && q.sigma > 0 && q.on_line.value_or(true) &&
             std::abs(q.speed - p.speed) <= 2.0 * std::hypot(p.sigma, q.sigma);
    };
    if (!countsAlone(p, trusted_points) && (p.on_line || std::none_of(pairs.begin(), pairs.end(), agrees))) continue;
    speeds.push_back(p.speed);
    sigmas.push_back(p.sigma);
    newest = &p;
  }
  if (!newest) return std::nullopt;
  const Eigen::Vector2d u = newest->u;
  const double sigma = median(sigmas);
  VelocityEvidence v;
  v.velocity = median(speeds) * u;
  v.information = u * u.transpose() / (sigma * sigma);
  return v;
}

}  // namespace dlslot::backend
