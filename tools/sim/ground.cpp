#include "ground.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "path.hpp"
#include "rng.hpp"

namespace dlslot::sim {

Ground::Ground(const GroundSpec& spec, uint64_t key, const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) {
  Rng rng(key);
  const double share[3] = {0.5, 0.3, 0.2};  // of the slope budget, so the sum stays within max_slope
  for (int i = 0; i < 3; ++i) {
    const double wavelength = rng.uniform(spec.wavelength_m.lo, spec.wavelength_m.hi);
    const double dir = rng.uniform(0, 2 * M_PI);
    Wave& w = waves_[i];
    w.k = (2 * M_PI / wavelength) * Eigen::Vector2d(std::cos(dir), std::sin(dir));
    w.amplitude = share[i] * spec.max_slope / w.k.norm();
    w.phase = rng.uniform(0, 2 * M_PI);
    slope_bound_ += w.amplitude * w.k.norm();
  }
  origin_ = lo;
  nx_ = std::max(1, static_cast<int>(std::ceil((hi.x() - lo.x()) / kCell)));
  ny_ = std::max(1, static_cast<int>(std::ceil((hi.y() - lo.y()) / kCell)));
  raster_.assign(static_cast<size_t>(nx_) * ny_, Surface::Grass);
}

double Ground::height(const Eigen::Vector2d& p) const {
  double h = 0;
  for (const Wave& w : waves_) h += w.amplitude * std::sin(w.k.dot(p) + w.phase);
  return h;
}

Eigen::Vector2d Ground::gradient(const Eigen::Vector2d& p) const {
  Eigen::Vector2d g = Eigen::Vector2d::Zero();
  for (const Wave& w : waves_) g += w.amplitude * std::cos(w.k.dot(p) + w.phase) * w.k;
  return g;
}

Eigen::Vector3d Ground::normal(const Eigen::Vector2d& p) const {
  const Eigen::Vector2d g = gradient(p);
  return Eigen::Vector3d(-g.x(), -g.y(), 1.0).normalized();
}

double Ground::intersect(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double max_s, double guess) const {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  // Along the ray each wave is sin(alpha + beta s): f(s) = o_z + s d_z - h(s) is the ray's height
  // above the ground, f' = d_z - h'(s), and |h'| <= G |d_xy| (G: the slope bound).
  double alpha[3], beta[3];
  for (int i = 0; i < 3; ++i) {
    alpha[i] = waves_[i].k.dot(o.head<2>()) + waves_[i].phase;
    beta[i] = waves_[i].k.dot(d.head<2>());
  }
  auto eval = [&](double s, double& f, double& rate) {
    double h = 0, dh = 0;
    for (int i = 0; i < 3; ++i) {
      double sn, cs;
      sincos(alpha[i] + beta[i] * s, &sn, &cs);
      h += waves_[i].amplitude * sn;
      dh += waves_[i].amplitude * beta[i] * cs;
    }
    f = o.z() + s * d.z() - h;
    rate = d.z() - dh;
  };
  const double g_xy = slope_bound_ * d.head<2>().norm();
  if (d.z() + g_xy < 0) {
    // Steeper down than any slope: f falls monotonically, one root. Newton, kept inside the
    // bracket f(lo) > 0 > f(hi) (bisecting, or doubling while hi is unknown, when it leaves it).
    // The search starts at `guess` (the neighbouring ray's hit): f(0) > 0 as the sensor is above
    // the ground, so [0, inf) brackets the root from the start.
    double lo = 0, hi = kInf, s = std::max(0.0, guess), f, rate;
    eval(s, f, rate);
    for (int it = 0; it < 60; ++it) {
      (f > 0 ? lo : hi) = s;
      if (lo > max_s) return kInf;
      if (std::abs(f) < 1e-6 || hi - lo < 1e-9) break;
      const double next = s - f / rate;
      // A Newton step this small leaves an error of about (f'' / 2 f') step^2 < 1e-9 m on slopes
      // this gentle: done without another evaluation.
      if (std::abs(next - s) < 1e-4 && next > lo && next < hi) return next > max_s ? kInf : next;
      s = next > lo && next < hi ? next : std::isfinite(hi) ? 0.5 * (lo + hi) : 2 * lo + 1;
      eval(s, f, rate);
    }
    return s > max_s ? kInf : s;
  }
  // Near-horizontal rays may touch the ground more than once: step f / (G |d_xy| - d_z) at a
  // time, which never passes the first root ("sphere tracing"), then Newton once close.
  const double descent = g_xy - d.z();
  if (descent <= 0) return kInf;  // climbs faster than any slope
  double s = 0, f, rate;
  eval(0, f, rate);
  if (f <= 0) return 0.0;
  while (f > 0.05) {
    s += f / descent;
    if (s > max_s) return kInf;
    eval(s, f, rate);
  }
  for (int it = 0; it < 6 && std::abs(f) > 1e-6 && rate < 0; ++it) {
    s -= f / rate;
    eval(s, f, rate);
  }
  return s > max_s ? kInf : s;
}

void Ground::paint(const Eigen::Vector2d& p, Surface s, bool only_grass) {
  const int ix = static_cast<int>(std::floor((p.x() - origin_.x()) / kCell));
  const int iy = static_cast<int>(std::floor((p.y() - origin_.y()) / kCell));
  if (ix < 0 || iy < 0 || ix >= nx_ || iy >= ny_) return;
  Surface& cell = raster_[static_cast<size_t>(iy) * nx_ + ix];
  if (!only_grass || cell == Surface::Grass) cell = s;
}

void Ground::paintRoad(const Path& centre, const RoadSpec& road) {
  // Lines between adjacent lanes: solid where the direction changes (sign of the offset), dashed
  // (3 m painted, 6 m gap) between lanes driving the same way.
  std::vector<double> lanes = road.lanes;
  std::sort(lanes.begin(), lanes.end());
  std::vector<std::pair<double, bool>> lines;  // offset, dashed
  for (size_t i = 1; i < lanes.size(); ++i)
    lines.emplace_back(0.5 * (lanes[i - 1] + lanes[i]), (lanes[i - 1] > 0) == (lanes[i] > 0));
  const double half_carriage = 0.5 * road.carriageway_m, half_clear = 0.5 * road.clear_m;
  for (double s = 0; s <= centre.length(); s += 0.5 * kCell) {
    const Path::Sample smp = centre.at(s);
    const Eigen::Vector2d left(-std::sin(smp.heading), std::cos(smp.heading));
    // Asphalt always wins over other roads' sidewalks (junctions); sidewalks only cover grass.
    for (double l = -half_clear; l <= half_clear; l += 0.5 * kCell) {
      if (std::abs(l) <= half_carriage)
        paint(smp.p + l * left, Surface::Asphalt, false);
      else
        paint(smp.p + l * left, Surface::Sidewalk, true);
    }
    for (const auto& [offset, dashed] : lines) {
      if (dashed && std::fmod(s, 9.0) > 3.0) continue;
      for (double w = -0.075; w <= 0.075; w += 0.5 * kCell) paint(smp.p + (offset + w) * left, Surface::Paint, false);
    }
  }
}

Surface Ground::surface(const Eigen::Vector2d& p) const {
  const int ix = static_cast<int>(std::floor((p.x() - origin_.x()) / kCell));
  const int iy = static_cast<int>(std::floor((p.y() - origin_.y()) / kCell));
  if (ix < 0 || iy < 0 || ix >= nx_ || iy >= ny_) return Surface::Grass;
  return raster_[static_cast<size_t>(iy) * nx_ + ix];
}

}  // namespace dlslot::sim
