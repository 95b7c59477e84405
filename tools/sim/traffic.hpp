// The objects and the ego vehicle over time. Vehicles, cyclists and pedestrians move along their
// lanes, routes or crossings with a speed profile (cruise, speed changes, stops, traffic lights)
// and keep their distance to whoever is ahead on the same lane (the interaction term of the
// Intelligent Driver Model). Objects whose paths would still overlap another's (or the ego's, or
// a structure) at some frame are removed, so no two solids ever intersect. Parked vehicles stand
// along the roads' parking strips.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "dlslot/types.hpp"
#include "world.hpp"

namespace dlslot::sim {

struct Agent {
  std::string type;
  Eigen::Vector3d size = Eigen::Vector3d::Zero();  // l, w, h
  std::vector<Solid> parts;                        // in the box's own frame
  bool parked = false;
  // Per frame: the box's footprint centre (map frame), heading and speed.
  std::vector<Eigen::Vector2d> xy;
  std::vector<double> heading, speed;
};

struct Motion {
  std::vector<Agent> agents;
  std::vector<Pose> ego;  // T_map_lidar per frame
  int removed = 0;        // objects dropped because their paths would overlap
  // The frame from which the ego stands at the end of its path, or queued behind the traffic
  // standing there, to the last frame (-1: never): a run longer than its
  // scenario was written for. The world goes on (the ground is endless, the roadside and the
  // traffic are still there), so its scans stay valid; the ego just stops moving.
  int ego_path_end_frame = -1;
};

// The ego body's pitch, roll and heave on its suspension (EgoSpec), as a pose in the lidar frame
// of the road-following pose: T_map_lidar = T_road * at(t, speed).
class BodyRide {
 public:
  BodyRide(const EgoSpec& ego, uint64_t key);
  // The ride at time t while the vehicle drives at `speed` m/s: the waves scaled by
  // min(1, speed / EgoSpec::ride_full_speed_mps) when that is set (a vehicle at rest does not rock).
  Pose at(double t, double speed) const;
  double value(int axis, double t) const;  // axis 0 pitch (rad), 1 roll (rad), 2 heave (m)

 private:
  struct Wave {
    double amplitude = 0, hz = 0, phase = 0;
  };
  double full_speed_mps_ = 0;
  std::array<std::array<Wave, 3>, 3> waves_{};
};

Motion simulateMotion(const Scenario& scenario, const World& world);

// The agent's box in the map frame at a frame (geometric centre: ground height + h/2).
Box agentBox(const Agent& agent, int frame, const Ground& ground);
// Its solids in the map frame at that frame, appended to `out` with owner = `index`.
void agentSolids(const Agent& agent, int index, int frame, const Ground& ground, std::vector<Solid>& out);

}  // namespace dlslot::sim
