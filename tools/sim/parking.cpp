#include "parking.hpp"

#include <cmath>

#include "object_shape.hpp"
#include "rng.hpp"

namespace dlslot::sim {

std::vector<Agent> parkVehicles(const Scenario& sc, const World& world) {
  std::vector<Agent> parked;
  std::vector<Solid> boxes;
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
        const Eigen::Vector2d xy =
            at.p + side * ps.offset_m * Eigen::Vector2d(-std::sin(at.heading), std::cos(at.heading));
        // Parallel parkers face the traffic of their side; stall parkers face in or out.
        double heading = at.heading + (side > 0 ? M_PI : 0.0);
        if (ps.angle > 0) heading = at.heading + side * ps.angle + (rng.chance(0.5) ? M_PI : 0.0);
        heading = wrapAngle(heading);
        const Solid box = Solid::box(Eigen::Vector3d(xy.x(), xy.y(), world.ground->height(xy) + 0.5 * ag.size.z()),
                                     ag.size, heading, 0.0f);
        bool free = world.keepsOffRoads(box, &road, 1.5);
        for (const Solid& o : boxes) free = free && !overlaps(box, o, 0.3);
        const Eigen::Vector2d ext = Eigen::Vector2d::Constant(box.radiusXY() + 0.5);
        for (int i : world.grid->near(xy - ext, xy + ext)) free = free && !overlaps(box, world.grid->solids()[i], 0.3);
        if (!free) continue;
        boxes.push_back(box);
        ag.xy.assign(sc.frames, xy);
        ag.heading.assign(sc.frames, heading);
        ag.speed.assign(sc.frames, 0.0);
        parked.push_back(ag);
      }
    }
  }
  return parked;
}

}  // namespace dlslot::sim
