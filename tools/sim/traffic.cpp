#include "traffic.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <stdexcept>

#include "object_shape.hpp"
#include "rng.hpp"

namespace dlslot::sim {
namespace {

constexpr double kSubstep = 0.01;  // s, integration step
const Eigen::Vector3d kEgoSize(4.6, 1.9, 1.6);

// Target speed over time: knots joined by smoothsteps, so accelerations are continuous.
class SpeedProfile {
 public:
  explicit SpeedProfile(std::vector<std::pair<double, double>> knots) : k_(std::move(knots)) {}
  double speed(double t) const { return eval(t, false); }
  double rate(double t) const { return eval(t, true); }

 private:
  double eval(double t, bool derivative) const {
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
  std::vector<std::pair<double, double>> k_;
};

// Following behaviour (IDM interaction term): a = a_max (1 - (s*/gap)^2), s* = s0 + v T + v dv / (2 sqrt(a b)).
struct Following {
  double a_max, b, s0, T;
};
Following followingOf(const std::string& type) {
  if (type == "Pedestrian") return {0.8, 1.0, 0.6, 0.6};
  if (type == "Cyclist") return {1.0, 1.5, 1.0, 0.8};
  return {1.5, 2.0, 2.0, 0.9};
}

struct Mover {
  int agent = -1;  // -1: the ego
  std::shared_ptr<const Path> path;
  std::string lane;  // movers on the same lane keep their distance
  double half_length = 0, s0 = 0, v0 = 0;
  SpeedProfile profile{{}};
  Following follow{};
  bool obeys_signals = true;  // pedestrians cross on their own schedule
  std::vector<std::pair<double, const SignalSpec*>> stops;  // stop positions before signalled junctions
};

std::string pathKey(const PathSpec& p) {
  if (p.crossing_s_m) return "crossing:" + p.road + ":" + std::to_string(*p.crossing_s_m);
  if (p.route) return "";  // a route is its own lane (a unique key is given below)
  return "road:" + p.road + ":" + std::to_string(p.lane);
}

// Where signals stop this path: just before it enters a junction disk along the signal's axis.
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

bool isRed(const SignalSpec& sig, double t) {
  for (const Interval& r : sig.red)
    if (t >= r.lo && t < r.hi) return true;
  return false;
}

// Cruise speed with random changes and perhaps one stop, as profile knots.
SpeedProfile agentProfile(const TrafficSpec& spec, double v0, double start_time, double duration,
                          const std::string& type, Rng& rng) {
  const double accel = type == "Pedestrian" ? 0.6 : 1.2;
  std::vector<std::pair<double, double>> knots;
  double t = 0, v = v0;
  if (start_time > 0) {
    knots = {{0.0, 0.0}, {start_time, 0.0}};
    t = start_time + v0 / accel;
  }
  knots.emplace_back(t, v0);
  struct Event {
    double time, speed, hold;
  };
  std::vector<Event> events;
  const int changes = rng.poisson(spec.speed_changes);
  for (int i = 0; i < changes; ++i)
    events.push_back({rng.uniform(0, duration), std::max(0.3, v0 * rng.uniform(0.6, 1.3)), 0.0});
  if (rng.chance(spec.stop_probability)) events.push_back({rng.uniform(0.1, 0.7) * duration, 0.0, rng.uniform(3, 10)});
  std::sort(events.begin(), events.end(), [](const Event& a, const Event& b) { return a.time < b.time; });
  for (const Event& e : events) {
    if (e.time <= t) continue;  // overlaps the previous change: skip it
    knots.emplace_back(e.time, v);
    t = e.time + std::abs(e.speed - v) / accel + 0.5;
    knots.emplace_back(t, e.speed);
    if (e.hold > 0) {  // stand, then resume the cruise speed
      knots.emplace_back(t + e.hold, 0.0);
      t += e.hold + v0 / accel + 0.5;
      knots.emplace_back(t, v0);
      v = v0;
    } else {
      v = e.speed;
    }
  }
  return SpeedProfile(knots);
}

std::string pickClass(const std::map<std::string, double>& weights, Rng& rng) {
  double total = 0;
  for (const auto& kv : weights) total += kv.second;
  double u = rng.uniform(0, total);
  for (const auto& kv : weights) {
    if (u < kv.second) return kv.first;
    u -= kv.second;
  }
  return weights.rbegin()->first;
}

// Arc length and speed of every mover at every frame.
struct Trace {
  std::vector<std::vector<double>> s, v;  // [mover][frame]
};

Trace simulate(const std::vector<Mover>& movers, const std::vector<bool>& alive, const Scenario& sc) {
  const size_t n = movers.size();
  Trace tr;
  tr.s.assign(n, std::vector<double>(sc.frames));
  tr.v.assign(n, std::vector<double>(sc.frames));
  std::vector<double> s(n), v(n);
  for (size_t i = 0; i < n; ++i) {
    s[i] = movers[i].s0;
    v[i] = movers[i].v0;
  }
  std::map<std::string, std::vector<size_t>> lanes;
  for (size_t i = 0; i < n; ++i)
    if (alive[i]) lanes[movers[i].lane].push_back(i);
  const int substeps = std::max(1, static_cast<int>(std::lround(sc.frame_period_s / kSubstep)));
  const double dt = sc.frame_period_s / substeps;
  std::vector<double> a(n);
  for (int f = 0; f < sc.frames; ++f) {
    for (size_t i = 0; i < n; ++i) {
      tr.s[i][f] = s[i];
      tr.v[i][f] = v[i];
    }
    if (f + 1 == sc.frames) break;
    for (int k = 0; k < substeps; ++k) {
      const double t = f * sc.frame_period_s + k * dt;
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
        const double s_star = fo.s0 + std::max(0.0, v[i] * fo.T + v[i] * (v[i] - lead_v) / (2 * std::sqrt(fo.a_max * fo.b)));
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

Solid footprintBox(const Eigen::Vector2d& xy, double heading, const Eigen::Vector3d& size, const Ground& ground) {
  return Solid::box(Eigen::Vector3d(xy.x(), xy.y(), ground.height(xy) + 0.5 * size.z()), size, heading, 0.0f);
}

Pose egoPose(const Eigen::Vector2d& xy, double heading, const Ground& ground, double height) {
  // The vehicle stands on the ground: its z axis is the ground normal, x the heading in that plane.
  const Eigen::Vector3d n = ground.normal(xy);
  const Eigen::Vector3d fwd(std::cos(heading), std::sin(heading), 0.0);
  const Eigen::Vector3d x = (fwd - fwd.dot(n) * n).normalized();
  Pose T = Pose::Identity();
  T.linear().col(0) = x;
  T.linear().col(1) = n.cross(x);
  T.linear().col(2) = n;
  T.translation() = Eigen::Vector3d(xy.x(), xy.y(), ground.height(xy)) + height * n;
  return T;
}

}  // namespace

Box agentBox(const Agent& agent, int frame, const Ground& ground) {
  Box b;
  const Eigen::Vector2d xy = agent.xy[frame];
  b.center = Eigen::Vector3d(xy.x(), xy.y(), ground.height(xy) + 0.5 * agent.size.z());
  b.size = agent.size;
  b.yaw = agent.heading[frame];
  b.type = agent.type;
  return b;
}

void agentSolids(const Agent& agent, int index, int frame, const Ground& ground, std::vector<Solid>& out) {
  const Box b = agentBox(agent, frame, ground);
  const double c = std::cos(b.yaw), s = std::sin(b.yaw);
  for (Solid p : agent.parts) {
    const Eigen::Vector3d off = p.center;
    p.center = b.center + Eigen::Vector3d(c * off.x() - s * off.y(), s * off.x() + c * off.y(), off.z());
    const double cy = p.cos_yaw, sy = p.sin_yaw;  // part yaw relative to the object
    p.cos_yaw = c * cy - s * sy;
    p.sin_yaw = s * cy + c * sy;
    p.owner = index;
    out.push_back(p);
  }
}

Motion simulateMotion(const Scenario& sc, const World& world) {
  const Ground& ground = *world.ground;
  const double duration = sc.frames * sc.frame_period_s;
  std::vector<Mover> movers;
  std::vector<Agent> agents;  // agents[i] belongs to movers[i + 1] (movers[0] is the ego)

  {  // the ego
    Mover ego;
    ego.path = std::make_shared<Path>(world.pathOf(sc.ego.path));
    ego.lane = sc.ego.path.route ? "route:ego" : pathKey(sc.ego.path);
    ego.half_length = 0.5 * kEgoSize.x();
    ego.s0 = sc.ego.start_s_m;
    ego.profile = SpeedProfile(sc.ego.speed_profile);
    ego.v0 = ego.profile.speed(0);
    ego.follow = followingOf("Car");
    ego.stops = stopsOn(*ego.path, sc);
    movers.push_back(ego);
  }
  for (size_t k = 0; k < sc.traffic.size(); ++k) {
    const TrafficSpec& spec = sc.traffic[k];
    auto forward = std::make_shared<Path>(world.pathOf(spec.path));
    std::shared_ptr<Path> backward;
    const std::string key = spec.path.route ? "route:" + std::to_string(k) : pathKey(spec.path);
    for (int i = 0; i < spec.count; ++i) {
      Rng rng(streamKey({sc.seed, 3, k, static_cast<uint64_t>(i)}));
      Mover m;
      m.agent = static_cast<int>(agents.size());
      m.path = forward;
      m.lane = key;
      if (spec.path.crossing_s_m && rng.chance(0.5)) {  // pedestrians cross both ways, keeping right
        if (!backward) backward = std::make_shared<Path>(forward->reversed().offset(1.2));
        m.path = backward;
        m.lane = key + ":back";
      }
      Agent ag;
      ag.type = pickClass(spec.classes, rng);
      ag.size = sampleSize(ag.type, rng);
      ag.parts = objectParts(ag.type, ag.size, static_cast<float>(rng.uniform(0.08, 0.5)));
      m.half_length = 0.5 * ag.size.x();
      m.follow = followingOf(ag.type);
      m.obeys_signals = ag.type != "Pedestrian";
      const double cruise = rng.uniform(spec.speed_mps.lo, spec.speed_mps.hi);
      const double start_time = rng.uniform(spec.start_time_s.lo, spec.start_time_s.hi);
      m.v0 = start_time > 0 ? 0.0 : cruise;
      m.profile = agentProfile(spec, cruise, start_time, duration, ag.type, rng);
      m.stops = stopsOn(*m.path, sc);
      // A place on the lane at the start: its share of the interval (so `count` agents spread
      // over it), moved forward or back where needed to keep the following distance to everyone.
      const double lo = spec.start_s_m.hi > spec.start_s_m.lo ? spec.start_s_m.lo : 0.0;
      const double hi = spec.start_s_m.hi > spec.start_s_m.lo ? spec.start_s_m.hi : m.path->length();
      const double slot = (hi - lo) / spec.count;
      const double want = lo + slot * (i + rng.uniform(0.3, 0.7));
      auto free = [&](double s) {
        for (const Mover& o : movers)
          if (o.lane == m.lane &&
              std::abs(o.s0 - s) < o.half_length + m.half_length + m.follow.s0 + m.follow.T * std::max(m.v0, o.v0))
            return false;
        return true;
      };
      bool placed = false;
      for (double shift = 0; shift <= 0.5 * slot && !placed; shift += 1.0)
        for (double s : {want + shift, want - shift})
          if (!placed && s >= lo && s <= hi && free(s)) {
            m.s0 = s;
            placed = true;
          }
      if (!placed) continue;
      movers.push_back(m);
      agents.push_back(ag);
    }
  }
  const size_t num_moving = agents.size();

  // Parked vehicles along parking strips, clear of lanes, junctions, structures and each other.
  std::vector<Solid> parked_boxes;
  for (size_t r = 0; r < world.roads.size(); ++r) {
    const Road& road = world.roads[r];
    if (!road.spec->parking) continue;
    const ParkingSpec& ps = *road.spec->parking;
    Rng rng(streamKey({sc.seed, 4, r}));
    for (int side : {-1, 1}) {
      for (double s = rng.uniform(0, ps.spacing_m.hi); s < road.centre.length();
           s += rng.uniform(ps.spacing_m.lo, ps.spacing_m.hi)) {
        if (!rng.chance(ps.fill)) continue;
        Agent ag;
        ag.type = rng.chance(0.85) ? "Car" : "Van";
        ag.size = sampleSize(ag.type, rng);
        ag.parts = objectParts(ag.type, ag.size, static_cast<float>(rng.uniform(0.08, 0.5)));
        ag.parked = true;
        const Path::Sample at = road.centre.at(s);
        const Eigen::Vector2d xy = at.p + side * ps.offset_m * Eigen::Vector2d(-std::sin(at.heading), std::cos(at.heading));
        // Parallel parkers face the traffic of their side; stall parkers face in or out.
        double heading = at.heading + (side > 0 ? M_PI : 0.0);
        if (ps.angle > 0) heading = at.heading + side * ps.angle + (rng.chance(0.5) ? M_PI : 0.0);
        heading = wrapAngle(heading);
        const Solid box = footprintBox(xy, heading, ag.size, ground);
        bool free = world.keepsOffRoads(box, &road, 1.5);
        for (const Solid& o : parked_boxes) free = free && !overlaps(box, o, 0.3);
        const Eigen::Vector2d ext = Eigen::Vector2d::Constant(box.radiusXY() + 0.5);
        for (int i : world.grid->near(xy - ext, xy + ext)) free = free && !overlaps(box, world.grid->solids()[i], 0.3);
        if (!free) continue;
        parked_boxes.push_back(box);
        ag.xy.assign(sc.frames, xy);
        ag.heading.assign(sc.frames, heading);
        ag.speed.assign(sc.frames, 0.0);
        agents.push_back(ag);
      }
    }
  }

  // Simulate, find the first overlaps, drop the less important party, repeat. Importance: the ego,
  // then vehicles, then pedestrians and cyclists (scenario order), parked vehicles last.
  auto priority = [&](size_t agent) {
    if (agent >= num_moving) return 3;
    return isVehicle(agents[agent].type) ? 1 : 2;
  };
  std::vector<bool> alive(movers.size(), true), parked_alive(agents.size() - num_moving, true);
  Motion out;
  Trace tr;
  for (;;) {
    tr = simulate(movers, alive, sc);
    // Boxes per frame: ego = index -1 in `who`.
    std::vector<int> remove;
    for (int f = 0; f < sc.frames && remove.empty(); ++f) {
      std::vector<Solid> boxes;
      std::vector<int> who;
      for (size_t i = 0; i < movers.size(); ++i) {
        if (!alive[i]) continue;
        const Path::Sample at = movers[i].path->at(tr.s[i][f]);
        const Eigen::Vector3d size = movers[i].agent < 0 ? kEgoSize : agents[movers[i].agent].size;
        boxes.push_back(footprintBox(at.p, at.heading, size, ground));
        who.push_back(movers[i].agent);
      }
      const size_t moving_boxes = boxes.size();
      for (size_t p = 0; p < parked_boxes.size(); ++p)
        if (parked_alive[p]) {
          boxes.push_back(parked_boxes[p]);
          who.push_back(static_cast<int>(num_moving + p));
        }
      for (size_t i = 0; i < moving_boxes; ++i) {
        for (size_t j = i + 1; j < boxes.size(); ++j) {
          if (!overlaps(boxes[i], boxes[j], 0.2)) continue;
          const int a = who[i], b = who[j];
          const int pa = a < 0 ? 0 : priority(a), pb = priority(b);
          const int loser = (pa < pb || (pa == pb && a < b)) ? b : a;
          if (loser < 0) throw std::runtime_error("scenario " + sc.name + ": the ego overlaps itself");
          remove.push_back(loser);
        }
        const Eigen::Vector2d c = boxes[i].center.head<2>(), ext = Eigen::Vector2d::Constant(boxes[i].radiusXY() + 0.5);
        for (int k : world.grid->near(c - ext, c + ext)) {
          if (!overlaps(boxes[i], world.grid->solids()[k], 0.05)) continue;
          if (who[i] < 0)
            throw std::runtime_error("scenario " + sc.name + ": the ego's path runs into a static structure at frame " +
                                     std::to_string(f));
          remove.push_back(who[i]);
        }
      }
    }
    if (remove.empty()) break;
    for (int r : remove) {
      if (static_cast<size_t>(r) >= num_moving) {
        if (parked_alive[r - num_moving]) ++out.removed;
        parked_alive[r - num_moving] = false;
        continue;
      }
      for (size_t i = 1; i < movers.size(); ++i)
        if (movers[i].agent == r && alive[i]) {
          alive[i] = false;
          ++out.removed;
        }
    }
  }

  for (int f = 0; f < sc.frames; ++f) {
    const Path::Sample at = movers[0].path->at(tr.s[0][f]);
    out.ego.push_back(egoPose(at.p, at.heading, ground, sc.sensor.height_m));
  }
  for (size_t i = 1; i < movers.size(); ++i) {
    if (!alive[i]) continue;
    Agent ag = agents[movers[i].agent];
    for (int f = 0; f < sc.frames; ++f) {
      const Path::Sample at = movers[i].path->at(tr.s[i][f]);
      ag.xy.push_back(at.p);
      ag.heading.push_back(at.heading);
      ag.speed.push_back(tr.v[i][f]);
    }
    out.agents.push_back(std::move(ag));
  }
  for (size_t p = 0; p < parked_boxes.size(); ++p)
    if (parked_alive[p]) out.agents.push_back(agents[num_moving + p]);
  return out;
}

}  // namespace dlslot::sim
