// A planar curve sampled by arc length: roads, lanes, the ego's and the agents' routes.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "scenario.hpp"

namespace dlslot::sim {

class Path {
 public:
  struct Sample {
    Eigen::Vector2d p = Eigen::Vector2d::Zero();
    double heading = 0.0;  // rad, direction of travel
  };
  struct Nearest {
    double s = 0.0;         // arc length of the nearest point
    double distance = 0.0;  // unsigned
    double lateral = 0.0;   // signed, positive left of the direction of travel
  };

  // Integrates the route's smoothed curvature (see RouteSpec) into samples every `step` metres.
  static Path fromRoute(const RouteSpec& route, double step = 0.25);
  static Path line(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double step = 0.25);

  Path offset(double left_m) const;  // the parallel curve (a lane of a road)
  Path reversed() const;             // the same curve driven the other way

  double length() const { return s_.back(); }
  // Position and heading at arc length s; beyond the ends the curve continues straight.
  Sample at(double s) const;
  Nearest nearest(const Eigen::Vector2d& p) const;
  // The first arc length at which the curve is within `radius` of `c` (nullopt if never).
  std::optional<double> entersDisk(const Eigen::Vector2d& c, double radius) const;
  const std::vector<Sample>& samples() const { return samples_; }

 private:
  static Path fromPoints(std::vector<Sample> samples);
  std::vector<Sample> samples_;
  std::vector<double> s_;  // cumulative arc length of each sample
  double max_step_ = 0.0;
};

}  // namespace dlslot::sim
