// The ground: a smooth surface of gentle slopes (a few long-wavelength waves, grade bounded by
// GroundSpec::max_slope) and a raster of what it is made of (asphalt, sidewalk, grass, paint),
// which sets the intensity of its returns.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "scenario.hpp"

namespace dlslot::sim {

class Path;

enum class Surface : uint8_t { Grass, Asphalt, Sidewalk, Paint };

class Ground {
 public:
  // `lo`, `hi`: the area that gets a surface raster (outside it: grass).
  Ground(const GroundSpec& spec, uint64_t key, const Eigen::Vector2d& lo, const Eigen::Vector2d& hi);

  double height(const Eigen::Vector2d& p) const;
  Eigen::Vector2d gradient(const Eigen::Vector2d& p) const;
  Eigen::Vector3d normal(const Eigen::Vector2d& p) const;
  // Distance along the unit ray (o, d) to the ground, or +infinity if beyond max_s; o must be above
  // the ground. `guess` (e.g. the previous ray's distance) only speeds the search up.
  double intersect(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double max_s, double guess = 0.0) const;

  // Paints a road: asphalt over the carriageway, sidewalk out to `clear_m`, dashed lane lines
  // between lanes driving the same way and a solid line between the directions.
  void paintRoad(const Path& centre, const RoadSpec& road);
  Surface surface(const Eigen::Vector2d& p) const;

 private:
  void paint(const Eigen::Vector2d& p, Surface s, bool only_grass);
  struct Wave {
    Eigen::Vector2d k = Eigen::Vector2d::Zero();  // wave vector, rad/m
    double amplitude = 0.0, phase = 0.0;
  };
  std::array<Wave, 3> waves_;
  double slope_bound_ = 0.0;  // bound on |gradient|

  static constexpr double kCell = 0.25;  // raster cell, m
  Eigen::Vector2d origin_;
  int nx_ = 0, ny_ = 0;
  std::vector<Surface> raster_;
};

}  // namespace dlslot::sim
