#include "traffic.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <stdexcept>

#include "lane_motion.hpp"
#include "object_shape.hpp"
#include "parking.hpp"
#include "rng.hpp"

namespace dlslot::sim {
namespace {

const Eigen::Vector3d kEgoSize(4.6, 1.9, 1.6);

std::string pathKey(const PathSpec& p) {
  if (p.crossing_s_m) return "crossing:" + p.road + ":" + std::to_string(*p.crossing_s_m);
  if (p.route) return "";  // a route is its own lane (a unique key is given below)
  return "road:" + p.road + ":" + std::to_string(p.lane);
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

BodyRide::BodyRide(const EgoSpec& ego, uint64_t key) : full_speed_mps_(ego.ride_full_speed_mps) {
  Rng rng(key);
  // Three sinusoids of equal amplitude have an rms of amplitude * sqrt(3/2).
  const double scale[3] = {ego.body_pitch_roll, ego.body_pitch_roll, ego.body_heave_m};
  for (int axis = 0; axis < 3; ++axis)
    for (Wave& w : waves_[axis]) {
      w.amplitude = scale[axis] / std::sqrt(1.5);
      w.hz = rng.uniform(0.7, 2.5);
      w.phase = rng.uniform(0, 2 * M_PI);
    }
}

double BodyRide::value(int axis, double t) const {
  double v = 0;
  for (const Wave& w : waves_[axis]) v += w.amplitude * std::sin(2 * M_PI * w.hz * t + w.phase);
  return v;
}

Pose BodyRide::at(double t, double speed) const {
  const double excitation = full_speed_mps_ > 0 ? std::clamp(speed / full_speed_mps_, 0.0, 1.0) : 1.0;
  Pose T = Pose::Identity();
  T.linear() = (Eigen::AngleAxisd(excitation * value(1, t), Eigen::Vector3d::UnitX()) *
                Eigen::AngleAxisd(excitation * value(0, t), Eigen::Vector3d::UnitY()))
                   .toRotationMatrix();
  T.translation().z() = excitation * value(2, t);
  return T;
}

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

  // Parked vehicles, with their footprints for the overlap checks.
  for (Agent& ag : parkVehicles(sc, world)) agents.push_back(std::move(ag));
  std::vector<Solid> parked_boxes;
  for (size_t i = num_moving; i < agents.size(); ++i) {
    const Box b = agentBox(agents[i], 0, ground);
    parked_boxes.push_back(Solid::box(b.center, b.size, b.yaw, 0.0f));
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
    tr = simulateLanes(movers, alive, sc.frames, sc.frame_period_s);
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

  // Standing (under 0.1 m/s) from then on to the last frame, within 100 m of its path's end: at
  // the end, or queued behind the traffic standing there.
  const Mover& ego = movers[0];
  for (int f = sc.frames - 1; f >= 0 && tr.v[0][f] < 0.1; --f)
    if (ego.path->length() - tr.s[0][f] < 100.0) out.ego_path_end_frame = f;
  const BodyRide ride(sc.ego, streamKey({sc.seed, 10}));
  for (int f = 0; f < sc.frames; ++f) {
    const Path::Sample at = movers[0].path->at(tr.s[0][f]);
    out.ego.push_back(egoPose(at.p, at.heading, ground, sc.sensor.height_m) * ride.at(f * sc.frame_period_s, tr.v[0][f]));
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
