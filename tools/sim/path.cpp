#include "path.hpp"

#include <algorithm>
#include <cmath>

#include "dlslot/types.hpp"

namespace dlslot::sim {

Path Path::fromPoints(std::vector<Sample> samples) {
  Path path;
  path.samples_ = std::move(samples);
  path.s_.assign(path.samples_.size(), 0.0);
  for (size_t i = 1; i < path.samples_.size(); ++i) {
    const double step = (path.samples_[i].p - path.samples_[i - 1].p).norm();
    path.s_[i] = path.s_[i - 1] + step;
    path.max_step_ = std::max(path.max_step_, step);
  }
  return path;
}

Path Path::fromRoute(const RouteSpec& route, double step) {
  // K(u) = integral of the piecewise-constant curvature, extended beyond the ends with the end
  // pieces' curvature; the smoothed curvature is its moving average over the transition length.
  std::vector<double> start_s{0.0};
  for (const auto& piece : route.pieces) start_s.push_back(start_s.back() + piece.length_m);
  const double total = start_s.back();
  auto K = [&](double u) {
    if (u <= 0) return u * route.pieces.front().curvature;
    if (u >= total) {
      double k = 0;
      for (const auto& piece : route.pieces) k += piece.length_m * piece.curvature;
      return k + (u - total) * route.pieces.back().curvature;
    }
    double k = 0;
    for (size_t i = 0; i < route.pieces.size(); ++i) {
      const double len = std::min(route.pieces[i].length_m, u - start_s[i]);
      if (len <= 0) break;
      k += len * route.pieces[i].curvature;
    }
    return k;
  };
  const double T = std::max(route.transition_m, 1e-3);
  auto curvature = [&](double s) { return (K(s + 0.5 * T) - K(s - 0.5 * T)) / T; };

  const int n = std::max(1, static_cast<int>(std::ceil(total / step)));
  const double ds = total / n;
  const int sub = 5;  // midpoint integration substeps per sample
  std::vector<Sample> samples;
  samples.reserve(n + 1);
  Sample cur{route.start, route.start_heading};
  samples.push_back(cur);
  double s = 0;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < sub; ++j) {
      const double h = ds / sub;
      const double mid_heading = cur.heading + 0.5 * h * curvature(s);
      cur.heading += h * curvature(s + 0.5 * h);
      cur.p += h * Eigen::Vector2d(std::cos(mid_heading), std::sin(mid_heading));
      s += h;
    }
    samples.push_back(cur);
  }
  return fromPoints(std::move(samples));
}

Path Path::line(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double step) {
  const double len = (b - a).norm();
  const int n = std::max(1, static_cast<int>(std::ceil(len / step)));
  const double heading = std::atan2(b.y() - a.y(), b.x() - a.x());
  std::vector<Sample> samples;
  for (int i = 0; i <= n; ++i) samples.push_back({a + (b - a) * (static_cast<double>(i) / n), heading});
  return fromPoints(std::move(samples));
}

Path Path::offset(double left_m) const {
  std::vector<Sample> out = samples_;
  for (Sample& smp : out) smp.p += left_m * Eigen::Vector2d(-std::sin(smp.heading), std::cos(smp.heading));
  return fromPoints(std::move(out));
}

Path Path::reversed() const {
  std::vector<Sample> out(samples_.rbegin(), samples_.rend());
  for (Sample& smp : out) smp.heading = wrapAngle(smp.heading + M_PI);
  return fromPoints(std::move(out));
}

Path::Sample Path::at(double s) const {
  if (s <= 0 || s >= length()) {
    const Sample& end = s <= 0 ? samples_.front() : samples_.back();
    const double beyond = s <= 0 ? s : s - length();
    return {end.p + beyond * Eigen::Vector2d(std::cos(end.heading), std::sin(end.heading)), end.heading};
  }
  const size_t i = std::upper_bound(s_.begin(), s_.end(), s) - s_.begin() - 1;
  const double seg = s_[i + 1] - s_[i];
  const double f = seg > 0 ? (s - s_[i]) / seg : 0.0;
  const Sample& a = samples_[i];
  const Sample& b = samples_[i + 1];
  return {a.p + f * (b.p - a.p), a.heading + f * wrapAngle(b.heading - a.heading)};
}

Path::Nearest Path::nearest(const Eigen::Vector2d& p) const {
  // Coarse pass over every k-th sample, then exact search only in windows whose lower bound
  // (coarse distance minus the window's half length) can still beat the best found.
  const size_t k = 16, n = samples_.size();
  std::vector<std::pair<double, size_t>> coarse;
  for (size_t i = 0; i < n; i += k) coarse.emplace_back((samples_[i].p - p).norm(), i);
  std::sort(coarse.begin(), coarse.end());
  const double reach = k * max_step_;  // arc length bound between a sample and its coarse sample
  Nearest best;
  best.distance = 1e300;
  for (const auto& [d, i] : coarse) {
    if (d - reach > best.distance) break;
    const size_t lo = i >= k ? i - k : 0, hi = std::min(n - 1, i + k);
    for (size_t j = lo; j < hi; ++j) {  // point-to-segment
      const Eigen::Vector2d a = samples_[j].p, ab = samples_[j + 1].p - a;
      const double len2 = ab.squaredNorm();
      const double f = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
      const Eigen::Vector2d q = a + f * ab;
      const double dist = (p - q).norm();
      if (dist < best.distance) {
        best.distance = dist;
        best.s = s_[j] + f * (s_[j + 1] - s_[j]);
        const Eigen::Vector2d dir = len2 > 0
                                        ? Eigen::Vector2d(ab / std::sqrt(len2))
                                        : Eigen::Vector2d(std::cos(samples_[j].heading), std::sin(samples_[j].heading));
        best.lateral = dir.x() * (p - q).y() - dir.y() * (p - q).x();
      }
    }
  }
  if (n == 1) best = {0.0, (samples_[0].p - p).norm(), 0.0};
  return best;
}

std::optional<double> Path::entersDisk(const Eigen::Vector2d& c, double radius) const {
  for (size_t i = 0; i < samples_.size(); ++i)
    if ((samples_[i].p - c).norm() <= radius) return s_[i];
  return std::nullopt;
}

}  // namespace dlslot::sim
