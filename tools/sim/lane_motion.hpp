// Longitudinal motion along lanes: each mover follows its path with a target speed profile and
// keeps its distance to whoever is ahead on the same lane, to red lights it can still stop for
// and to the end of its path (the interaction term of the Intelligent Driver Model, Treiber et
// al. 2000, capped by the profile's own acceleration).
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "path.hpp"
#include "scenario.hpp"

namespace dlslot::sim {

// Target speed over time: knots joined by smoothsteps, so accelerations are continuous.
class SpeedProfile {
 public:
  explicit SpeedProfile(std::vector<std::pair<double, double>> knots) : k_(std::move(knots)) {}
  double speed(double t) const { return eval(t, false); }
  double rate(double t) const { return eval(t, true); }

 private:
  double eval(double t, bool derivative) const;
  std::vector<std::pair<double, double>> k_;
};

// Following behaviour (IDM interaction term): a = a_max (1 - (s*/gap)^2), s* = s0 + v T + v dv / (2 sqrt(a b)).
struct Following {
  double a_max, b, s0, T;
};
Following followingOf(const std::string& type);

struct Mover {
  int agent = -1;  // -1: the ego
  std::shared_ptr<const Path> path;
  std::string lane;  // movers on the same lane keep their distance
  double half_length = 0, s0 = 0, v0 = 0;
  SpeedProfile profile{{}};
  Following follow{};
  bool obeys_signals = true;                                // pedestrians cross on their own schedule
  std::vector<std::pair<double, const SignalSpec*>> stops;  // stop positions before signalled junctions
};

// Where signals stop this path: just before it enters a junction disk along the signal's axis.
std::vector<std::pair<double, const SignalSpec*>> stopsOn(const Path& path, const Scenario& sc);

// Arc length and speed of every mover at every frame.
struct Trace {
  std::vector<std::vector<double>> s, v;  // [mover][frame]
};

// Integrates every live mover (alive[i]) in steps of 10 ms; samples at each frame.
Trace simulateLanes(const std::vector<Mover>& movers, const std::vector<bool>& alive, int frames,
                    double frame_period_s);

}  // namespace dlslot::sim
