// The static world: ground, roads and what stands along them (buildings, walls, poles, signs,
// trees, bushes, guard rails, barriers), generated from a scenario and a seed. Parked vehicles
// are objects (they are labelled), see traffic.hpp.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "grid.hpp"
#include "ground.hpp"
#include "path.hpp"
#include "scenario.hpp"

namespace dlslot::sim {

enum class StructureKind : uint8_t { Building, Wall, Pole, Sign, Tree, Bush, GuardRail, Barrier, NoiseWall };

struct Structure {
  StructureKind kind;
  Eigen::Vector3d base;  // ground point under its centre
};

struct Road {
  const RoadSpec* spec;
  Path centre;
};

struct World {
  std::vector<Road> roads;
  std::vector<Path> routes;  // the ego's and agents' own routes (not roads), kept clear too
  std::unique_ptr<Ground> ground;
  std::vector<Structure> structures;  // Solid::owner indexes this
  std::unique_ptr<SolidGrid> grid;    // every static solid

  const Road& road(const std::string& name) const;
  // The curve an agent's (or the ego's) centre follows, in its direction of travel. Lanes left of
  // a road's centreline (positive offsets) run against the road's direction.
  Path pathOf(const PathSpec& spec) const;
  // True when the solid keeps off the roads (so traffic never drives through it): out of `own`
  // road's carriageway (or, inside it, `lane_half_m` from every lane centre: a median), out of
  // other roads' clear zones, and `lane_half_m` from the ego's and agents' own routes.
  bool keepsOffRoads(const Solid& solid, const Road* own, double lane_half_m = 1.8) const;
};

// Builds the roads, the ground (slopes and surfaces) and the roadside structure.
World buildWorld(const Scenario& scenario);

}  // namespace dlslot::sim
