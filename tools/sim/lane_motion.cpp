#include "lane_motion.hpp"

#include <algorithm>
#include <cmath>
#include <map>

namespace dlslot::sim {
namespace {

constexpr double kSubstep = 0.01;  // s, integration step

bool isRed(const SignalSpec& sig, double t) {
  for (const Interval& r : sig.red)
    if (t >= r.lo && t < r.hi) return true;
  return false;
}

}  // namespace

double SpeedProfile::eval(double t, bool derivative) const {
  if (k_.empty()) return 0.0;
  if (t <= k_.front().first) return derivative ? 0.0 : k_.front().second;
  for (size_t i = 1; i < k_.size(); ++i) {
    if (t >= k_[i].first) continue;
    const double T = k_[i].first - k_[i - 1].first, dv = k_[i].second - k_[i - 1].second;
    const double u = (t - k_[i - 1].first) / T;
    return derivative ? dv * 6 * u * (1 - u) / T : k_[i - 1].second + dv * u * u * (3 - 2 * u);
  }
  return derivative ? 0.0 : k_.back().second;
}

Following followingOf(const std::string& type) {
  if (type == "Pedestrian") return {0.8, 1.0, 0.6, 0.6};
  if (type == "Cyclist") return {1.0, 1.5, 1.0, 0.8};
  return {1.5, 2.0, 2.0, 0.9};
}

std::vector<std::pair<double, const SignalSpec*>> stopsOn(const Path& path, const Scenario& sc) {
  std::vector<std::pair<double, const SignalSpec*>> out;
  for (const SignalSpec& sig : sc.signals) {
    const auto entry = path.entersDisk(sig.at, sig.radius_m);
    if (!entry || *entry <= 0) continue;
    if (std::abs(std::cos(path.at(*entry).heading - sig.axis)) < std::cos(M_PI / 4)) continue;
    out.emplace_back(*entry - 0.5, &sig);
  }
  return out;
}

Trace simulateLanes(const std::vector<Mover>& movers, const std::vector<bool>& alive, int frames,
                    double frame_period_s) {
  const size_t n = movers.size();
  Trace tr;
  tr.s.assign(n, std::vector<double>(frames));
  tr.v.assign(n, std::vector<double>(frames));
  std::vector<double> s(n), v(n);
  for (size_t i = 0; i < n; ++i) {
    s[i] = movers[i].s0;
    v[i] = movers[i].v0;
  }
  std::map<std::string, std::vector<size_t>> lanes;
  for (size_t i = 0; i < n; ++i)
    if (alive[i]) lanes[movers[i].lane].push_back(i);
  const int substeps = std::max(1, static_cast<int>(std::lround(frame_period_s / kSubstep)));
  const double dt = frame_period_s / substeps;
  std::vector<double> a(n);
  for (int f = 0; f < frames; ++f) {
    for (size_t i = 0; i < n; ++i) {
      tr.s[i][f] = s[i];
      tr.v[i][f] = v[i];
    }
    if (f + 1 == frames) break;
    for (int k = 0; k < substeps; ++k) {
      const double t = f * frame_period_s + k * dt;
      for (size_t i = 0; i < n; ++i) {
        if (!alive[i]) continue;
        const Mover& m = movers[i];
        const double front = s[i] + m.half_length;
        // Nearest obstacle ahead: a mover on the same lane, a red light it can still stop for, the path's end.
        double gap = m.path->length() - front, lead_v = 0;
        for (size_t j : lanes[m.lane]) {
          if (j == i || s[j] <= s[i]) continue;
          const double g = s[j] - movers[j].half_length - front;
          if (g < gap) {
            gap = g;
            lead_v = v[j];
          }
        }
        if (m.obeys_signals)
          for (const auto& [stop, sig] : m.stops) {
            const double g = stop - front;
            if (g > 0 && g < gap && isRed(*sig, t) && v[i] * v[i] / (2 * g) < 3.5) {
              gap = g;
              lead_v = 0;
            }
          }
        const Following& fo = m.follow;
        const double track = std::clamp(m.profile.rate(t) + (m.profile.speed(t) - v[i]) / 0.8, -6.0, 3.0);
        const double s_star =
            fo.s0 + std::max(0.0, v[i] * fo.T + v[i] * (v[i] - lead_v) / (2 * std::sqrt(fo.a_max * fo.b)));
        const double interact = gap > 0.05 ? fo.a_max * (1 - (s_star / gap) * (s_star / gap)) : -9.0;
        a[i] = std::max(-9.0, std::min(track, interact));
      }
      for (size_t i = 0; i < n; ++i) {
        if (!alive[i]) continue;
        v[i] = std::max(0.0, v[i] + a[i] * dt);
        s[i] += v[i] * dt;
      }
    }
  }
  return tr;
}

}  // namespace dlslot::sim
