#include "clear_mot.hpp"

#include <cmath>
#include <map>

#include "assignment.hpp"
#include "box_overlap.hpp"

namespace dlslot::eval {

ClearMot evaluateClearMot(const std::vector<TrackingFrame>& frames, const MatchCriterion& criterion) {
  ClearMot m;
  std::map<int, int> previous;    // label id -> track id, matched in the previous frame
  std::map<int, int> last_match;  // label id -> track id it was last matched to, any frame
  std::map<int, int> first_output;  // track id -> index of the first frame it was output in
  double distance_sum = 0, velocity_sq_sum = 0, heading_sq_sum = 0, unreversed_sq_sum = 0;
  for (size_t index = 0; index < frames.size(); ++index) {
    const TrackingFrame& f = frames[index];
    for (const Object& h : f.tracks) first_output.emplace(h.box.id, static_cast<int>(index));
    const int nt = static_cast<int>(f.truth.size()), nh = static_cast<int>(f.tracks.size());
    std::vector<int> track_of(nt, -1);
    std::vector<bool> taken(nh, false);
    // Keep last frame's correspondences that are still valid.
    for (int i = 0; i < nt; ++i) {
      const auto prev = previous.find(f.truth[i].box.id);
      if (prev == previous.end()) continue;
      for (int j = 0; j < nh; ++j)
        if (!taken[j] && f.tracks[j].box.id == prev->second && criterion.matches(f.truth[i].box, f.tracks[j].box)) {
          track_of[i] = j;
          taken[j] = true;
          break;
        }
    }
    // Match the rest optimally.
    std::vector<int> free_truth, free_tracks;
    for (int i = 0; i < nt; ++i)
      if (track_of[i] < 0) free_truth.push_back(i);
    for (int j = 0; j < nh; ++j)
      if (!taken[j]) free_tracks.push_back(j);
    const std::vector<int> col = assignAllowedPairs(
        static_cast<int>(free_truth.size()), static_cast<int>(free_tracks.size()), [&](int a, int b) -> std::optional<double> {
          const Box &g = f.truth[free_truth[a]].box, &h = f.tracks[free_tracks[b]].box;
          if (!criterion.matches(g, h)) return std::nullopt;
          return criterion.cost(g, h);
        });
    for (size_t a = 0; a < free_truth.size(); ++a)
      if (col[a] >= 0) track_of[free_truth[a]] = free_tracks[col[a]];

    std::map<int, int> current;
    int matched = 0;
    for (int i = 0; i < nt; ++i) {
      if (track_of[i] < 0) continue;
      const Object& g = f.truth[i];
      const Object& h = f.tracks[track_of[i]];
      ++matched;
      distance_sum += bevDistance(g.box, h.box);
      const auto last = last_match.find(g.box.id);
      if (last != last_match.end() && last->second != h.box.id) ++m.idsw;
      last_match[g.box.id] = h.box.id;
      current[g.box.id] = h.box.id;
      if (g.velocity && h.velocity)
        m.velocities.push_back({static_cast<int>(index), g.box.id, h.box.id, g.box.type, g.dynamic,
                                static_cast<int>(index) - first_output.at(h.box.id), *g.velocity, *h.velocity,
                                h.velocity_covariance, g.box.center.head<2>().norm()});
      if (g.dynamic && g.velocity && h.velocity) {
        velocity_sq_sum += (*g.velocity - *h.velocity).squaredNorm();
        ++m.velocity_pairs;
      }
      if (g.box.type == "Car" && g.dynamic && g.velocity && g.velocity->norm() >= ClearMot::kMovingSpeedMps) {
        const double d = std::remainder(h.box.yaw - g.box.yaw, 2.0 * M_PI) * 180.0 / M_PI;
        heading_sq_sum += d * d;
        ++m.heading_pairs;
        if (std::abs(d) > 90.0)
          ++m.heading_reversed;
        else
          unreversed_sq_sum += d * d;
      }
    }
    previous = std::move(current);
    m.num_truth += nt;
    m.tp += matched;
    m.fn += nt - matched;
    m.fp += nh - matched;
  }
  if (m.num_truth > 0) m.mota = 1.0 - static_cast<double>(m.fn + m.fp + m.idsw) / m.num_truth;
  if (m.tp > 0) m.motp_m = distance_sum / m.tp;
  if (m.velocity_pairs > 0) m.velocity_rmse_mps = std::sqrt(velocity_sq_sum / m.velocity_pairs);
  if (m.heading_pairs > 0) m.heading_rmse_deg = std::sqrt(heading_sq_sum / m.heading_pairs);
  if (m.heading_pairs > m.heading_reversed)
    m.heading_rmse_unreversed_deg = std::sqrt(unreversed_sq_sum / (m.heading_pairs - m.heading_reversed));
  return m;
}

}  // namespace dlslot::eval
