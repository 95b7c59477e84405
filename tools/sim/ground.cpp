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

double Ground::intersect(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double max_s) const {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  // f(s) = height of the ray above the ground. Its rate is at least d_z - G |d_xy| (G: slope
  // bound), so stepping f / (G |d_xy| - d_z) never passes the first root ("sphere tracing");
  // Newton polishes the root once the ray is close.
  const Eigen::Vector2d o2 = o.head<2>(), d2 = d.head<2>();
  const double descent = slope_bound_ * d2.norm() - d.z();
  if (descent <= 0) return kInf;  // the ray climbs faster than any slope
  double s = 0;
  double f = o.z() - height(o2);
  if (f <= 0) return 0.0;
  while (f > 0.05) {
    s += f / descent;
    if (s > max_s) return kInf;
    f = o.z() + s * d.z() - height(o2 + s * d2);
  }
  for (int it = 0; it < 6 && std::abs(f) > 1e-6; ++it) {
    const Eigen::Vector2d p = o2 + s * d2;
    const double rate = d.z() - gradient(p).dot(d2);
    if (rate >= 0) break;  // cannot happen this close above a gentle slope; keep the safe estimate
    s -= f / rate;
    f = o.z() + s * d.z() - height(o2 + s * d2);
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
