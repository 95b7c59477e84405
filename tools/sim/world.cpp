#include "world.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "rng.hpp"

namespace dlslot::sim {
namespace {

Eigen::Vector2d leftOf(double heading) { return {-std::sin(heading), std::cos(heading)}; }
Eigen::Vector2d along(double heading) { return {std::cos(heading), std::sin(heading)}; }

// Points on a solid's footprint outline (and its centre), for keep-off checks.
std::vector<Eigen::Vector2d> outline(const Solid& s) {
  std::vector<Eigen::Vector2d> pts{s.center.head<2>()};
  if (s.kind == SolidKind::Box) {
    const Eigen::Vector2d ax(s.cos_yaw, s.sin_yaw), ay(-s.sin_yaw, s.cos_yaw);
    const Eigen::Vector2d c = s.center.head<2>();
    const Eigen::Vector2d corner[4] = {c + s.half.x() * ax + s.half.y() * ay, c + s.half.x() * ax - s.half.y() * ay,
                                       c - s.half.x() * ax - s.half.y() * ay, c - s.half.x() * ax + s.half.y() * ay};
    for (int i = 0; i < 4; ++i) {
      const Eigen::Vector2d a = corner[i], b = corner[(i + 1) % 4];
      const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / 1.0)));
      for (int k = 0; k < n; ++k) pts.push_back(a + (b - a) * (static_cast<double>(k) / n));
    }
  } else {
    for (int k = 0; k < 8; ++k) pts.push_back(s.center.head<2>() + s.half.x() * along(k * M_PI / 4));
  }
  return pts;
}

class RoadsideBuilder {
 public:
  RoadsideBuilder(World& world, uint64_t key, const SensorSpec& sensor, uint64_t fence_key)
      : w_(world), rng_(key), sensor_(sensor), fence_key_(fence_key) {}

  void build(const Road& road) {
    const RoadsideSpec& rs = road.spec->roadside;
    for (int side : {-1, 1}) {
      if (rs.buildings > 0 || rs.walls > 0) buildings(road, side);
      if (rs.poles_every_m > 0) poles(road, side);
      if (rs.trees_every_m > 0) trees(road, side);
      if (rs.bushes_every_m > 0) bushes(road, side);
      if (rs.guard_rail_offset_m > 0) guardRail(road, side);
      if (rs.noise_walls > 0) noiseWalls(road, side);
    }
    if (rs.median_barrier) median(road);
  }

  std::vector<Solid> solids;

 private:
  // Adds a structure if all its parts keep off the roads and off what is already there.
  bool add(StructureKind kind, std::vector<Solid> parts, const Road& own) {
    for (const Solid& p : parts) {
      if (!w_.keepsOffRoads(p, &own)) return false;
      for (const Solid& q : solids)
        if (overlaps(p, q, 0.2)) return false;
    }
    const int id = static_cast<int>(w_.structures.size());
    const Eigen::Vector2d c = parts.front().center.head<2>();
    w_.structures.push_back({kind, Eigen::Vector3d(c.x(), c.y(), w_.ground->height(c))});
    for (Solid& p : parts) {
      p.owner = id;
      solids.push_back(p);
    }
    return true;
  }

  // An upright box standing on the ground (base buried below the lowest corner).
  Solid standing(const Eigen::Vector2d& c, double yaw, double length, double width, double height, float refl,
                 double lift = 0.0) {
    const Eigen::Vector2d ax = along(yaw), ay = leftOf(yaw);
    double low = w_.ground->height(c);
    for (int i = -1; i <= 1; i += 2)
      for (int j = -1; j <= 1; j += 2)
        low = std::min(low, w_.ground->height(c + 0.5 * (i * length * ax + j * width * ay)));
    const double z0 = lift > 0 ? w_.ground->height(c) + lift : low - 0.5;
    const double z1 = w_.ground->height(c) + lift + height;
    return Solid::box(Eigen::Vector3d(c.x(), c.y(), 0.5 * (z0 + z1)), Eigen::Vector3d(length, width, z1 - z0), yaw,
                      refl);
  }

  void buildings(const Road& road, int side) {
    const RoadsideSpec& rs = road.spec->roadside;
    const double L = road.centre.length();
    double s = rng_.uniform(0, 8);
    while (s < L) {
      const bool building = rng_.chance(rs.buildings);
      double length = building ? rng_.uniform(rs.building_length_m.lo, rs.building_length_m.hi) : rng_.uniform(8, 25);
      if (building) {
        const double depth = rng_.uniform(rs.building_depth_m.lo, rs.building_depth_m.hi);
        const double height = rng_.uniform(rs.building_height_m.lo, rs.building_height_m.hi);
        const double setback = rng_.chance(0.5) ? 0.0 : rng_.uniform(0.5, 4.0);
        const Path::Sample at = road.centre.at(s + 0.5 * length);
        const double yaw = at.heading + (rng_.chance(0.2) ? rng_.uniform(-0.2, 0.2) : 0.0);
        const double off = side * (rs.frontage_m + setback + 0.5 * depth);
        const Eigen::Vector2d c = at.p + off * leftOf(at.heading);
        const float refl = static_cast<float>(rng_.uniform(0.15, 0.45));
        std::vector<Solid> parts{standing(c, yaw, length, depth, height, refl)};
        // Varied outlines give LOAM its edges: an annex behind or beside, a setback upper storey.
        if (rng_.chance(0.35)) {
          const double al = length * rng_.uniform(0.4, 0.7), ad = depth * rng_.uniform(0.5, 1.0);
          const Eigen::Vector2d ac = c + side * (0.5 * depth + 0.5 * ad - 0.5) * leftOf(yaw) +
                                     rng_.uniform(-0.5, 0.5) * (length - al) * along(yaw);
          parts.push_back(standing(ac, yaw, al, ad, height * rng_.uniform(0.4, 1.3), refl));
        }
        if (rng_.chance(0.25) && height > 6) {
          const double ul = length * rng_.uniform(0.4, 0.8), ud = depth * rng_.uniform(0.4, 0.8);
          parts.push_back(standing(c + side * 0.25 * (depth - ud) * leftOf(yaw), yaw, ul, ud, rng_.uniform(2.5, 5),
                                   refl, height - 0.05));
        }
        if (!add(StructureKind::Building, parts, road)) length = rng_.uniform(3, 8);  // try again a bit further on
      }
      const double gap = building ? rng_.uniform(0.5, 6.0) : 0.0;
      const double open = building ? gap : length;
      if (open > 2.0 && rng_.chance(rs.walls)) {  // a wall or fence closing the gap along the frontage
        const double ws = s + (building ? length : 0.0);
        const Path::Sample at = road.centre.at(ws + 0.5 * open);
        const Eigen::Vector2d c = at.p + side * (rs.frontage_m + 0.15) * leftOf(at.heading);
        Solid wall = standing(c, at.heading, open, 0.3, rng_.uniform(1.2, 2.6), 0.3f);
        // Some are wire fences that many rays pass (a draw of their own, so the roadside's other
        // draws stay as they were). Thickness t passes exp(-t / mean_free_path) of square-on rays.
        if (sensor_.fence_pass > 0 && sensor_.fence_pass < 1 &&
            Rng(streamKey({fence_key_, walls_++})).chance(sensor_.fences)) {
          constexpr double kThick = 0.05;
          wall.half.y() = 0.5 * kThick;
          wall.reflectivity = 0.4f;
          wall.mean_free_path = static_cast<float>(-kThick / std::log(sensor_.fence_pass));
        }
        add(StructureKind::Wall, {wall}, road);
      }
      s += length + gap;
    }
  }

  void poles(const Road& road, int side) {
    const RoadsideSpec& rs = road.spec->roadside;
    for (double s = rng_.uniform(0, rs.poles_every_m); s < road.centre.length();
         s += rs.poles_every_m * rng_.uniform(0.8, 1.2)) {
      const Path::Sample at = road.centre.at(s);
      const Eigen::Vector2d c = at.p + side * rs.poles_offset_m * leftOf(at.heading);
      const double g = w_.ground->height(c);
      if (rng_.chance(0.3)) {  // a traffic sign: thin post, a plate facing the traffic
        const double h = rng_.uniform(2.2, 2.8);
        Solid plate =
            Solid::box(Eigen::Vector3d(c.x(), c.y(), g + h), Eigen::Vector3d(0.05, 0.7, 0.7), at.heading, 0.9f);
        add(StructureKind::Sign, {Solid::cylinder(c, g - 0.2, g + h, 0.04, 0.4f), plate}, road);
        continue;
      }
      const double h = rng_.uniform(6, 9), r = rng_.uniform(0.09, 0.15);
      std::vector<Solid> parts{Solid::cylinder(c, g - 0.2, g + h, r, 0.45f)};
      Solid arm =
          Solid::box(Eigen::Vector3d(c.x(), c.y(), g + h - 0.1), Eigen::Vector3d(0.12, 1.4, 0.12), at.heading, 0.45f);
      arm.center.head<2>() -= side * 0.7 * leftOf(at.heading);  // reaching over the road
      if (w_.keepsOffRoads(arm, &road)) parts.push_back(arm);
      add(StructureKind::Pole, parts, road);
    }
  }

  void trees(const Road& road, int side) {
    const RoadsideSpec& rs = road.spec->roadside;
    for (double s = rng_.uniform(0, rs.trees_every_m); s < road.centre.length();
         s += rs.trees_every_m * rng_.uniform(0.7, 1.3)) {
      const Path::Sample at = road.centre.at(s);
      const Eigen::Vector2d c = at.p + side * (rs.trees_offset_m + rng_.uniform(-0.3, 0.3)) * leftOf(at.heading);
      const double g = w_.ground->height(c);
      const double trunk = rng_.uniform(2.2, 3.5);
      double crown = rng_.uniform(1.5, 3.0);
      for (int attempt = 0; attempt < 3; ++attempt, crown *= 0.7) {  // smaller crowns where lanes are close
        const Solid t = Solid::cylinder(c, g - 0.2, g + trunk, rng_.uniform(0.12, 0.3), 0.2f);
        // The crown sits on the trunk: people walk under it.
        Solid k = Solid::sphere(Eigen::Vector3d(c.x(), c.y(), g + trunk + crown), crown, 0.12f);
        k.mean_free_path = static_cast<float>(sensor_.vegetation_mean_free_path_m);  // foliage
        if (add(StructureKind::Tree, {t, k}, road)) break;
      }
    }
  }

  void bushes(const Road& road, int side) {
    const RoadsideSpec& rs = road.spec->roadside;
    for (double s = rng_.uniform(0, rs.bushes_every_m); s < road.centre.length();
         s += rs.bushes_every_m * rng_.uniform(0.5, 1.5)) {
      const Path::Sample at = road.centre.at(s);
      const Eigen::Vector2d c = at.p + side * (rs.frontage_m + rng_.uniform(0, 15)) * leftOf(at.heading);
      const double r = rng_.uniform(0.6, 1.8);
      Solid bush = Solid::sphere(Eigen::Vector3d(c.x(), c.y(), w_.ground->height(c) + 0.3 * r), r, 0.15f);
      bush.mean_free_path = static_cast<float>(sensor_.vegetation_mean_free_path_m);
      add(StructureKind::Bush, {bush}, road);
    }
  }

  // Posts every 4 m and a rail between them, following the road.
  void guardRail(const Road& road, int side) {
    const double off = side * road.spec->roadside.guard_rail_offset_m;
    for (double s = 0; s + 4 <= road.centre.length(); s += 4) {
      const Path::Sample a = road.centre.at(s), m = road.centre.at(s + 2);
      const Eigen::Vector2d pc = a.p + off * leftOf(a.heading), rc = m.p + off * leftOf(m.heading);
      const double g = w_.ground->height(pc);
      Solid rail = Solid::box(Eigen::Vector3d(rc.x(), rc.y(), w_.ground->height(rc) + 0.6),
                              Eigen::Vector3d(4.02, 0.1, 0.32), m.heading, 0.55f);
      rail.center.head<2>() -= side * 0.1 * leftOf(m.heading);  // the rail hangs on the road side of its posts
      add(StructureKind::GuardRail, {Solid::cylinder(pc, g - 0.2, g + 0.75, 0.07, 0.4f), rail}, road);
    }
  }

  void median(const Road& road) {
    for (double s = 0; s + 5 <= road.centre.length(); s += 5) {
      const Path::Sample m = road.centre.at(s + 2.5);
      add(StructureKind::Barrier, {standing(m.p, m.heading, 5.0, 0.6, 0.9, 0.3f)}, road);
    }
  }

  void noiseWalls(const Road& road, int side) {
    const RoadsideSpec& rs = road.spec->roadside;
    double s = rng_.uniform(0, 50);
    while (s < road.centre.length()) {
      const double len = rng_.uniform(30, 120);
      if (rng_.chance(rs.noise_walls)) {
        const double h = rng_.uniform(3, 4.5);
        for (double p = s; p + 5 <= std::min(s + len, road.centre.length()); p += 5) {
          const Path::Sample m = road.centre.at(p + 2.5);
          const Eigen::Vector2d c = m.p + side * (rs.frontage_m + 0.2) * leftOf(m.heading);
          add(StructureKind::NoiseWall, {standing(c, m.heading, 5.0, 0.3, h, 0.25f)}, road);
        }
      }
      s += len + rng_.uniform(10, 60);
    }
  }

  World& w_;
  Rng rng_;
  const SensorSpec& sensor_;
  uint64_t fence_key_;
  uint64_t walls_ = 0;
};

}  // namespace

const Road& World::road(const std::string& name) const {
  for (const Road& r : roads)
    if (r.spec->name == name) return r;
  throw std::invalid_argument("no road named '" + name + "'");
}

Path World::pathOf(const PathSpec& spec) const {
  if (spec.route) return Path::fromRoute(*spec.route).offset(spec.lane);
  const Road& r = road(spec.road);
  if (spec.crossing_s_m) {  // from one sidewalk to the other, square to the road
    const Path::Sample at = r.centre.at(*spec.crossing_s_m);
    const double half = 0.5 * r.spec->clear_m - 0.5;
    return Path::line(at.p - half * leftOf(at.heading), at.p + half * leftOf(at.heading));
  }
  const Path lane = r.centre.offset(spec.lane);
  return spec.lane > 0 ? lane.reversed() : lane;
}

bool World::keepsOffRoads(const Solid& solid, const Road* own, double lane_half_m) const {
  const std::vector<Eigen::Vector2d> pts = outline(solid);
  for (const Road& r : roads) {
    const double reach = 0.5 * r.spec->clear_m + solid.radiusXY();
    if (r.centre.nearest(solid.center.head<2>()).distance > reach + 1.0) continue;  // far from this road
    for (const Eigen::Vector2d& p : pts) {
      const Path::Nearest n = r.centre.nearest(p);
      if (&r != own) {
        if (n.distance < 0.5 * r.spec->clear_m) return false;
        continue;
      }
      if (n.s <= 0 || n.s >= r.centre.length()) continue;  // beyond the road's ends
      if (std::abs(n.lateral) >= 0.5 * r.spec->carriageway_m) continue;
      // Inside the carriageway only between lanes (a median barrier).
      for (double lane : r.spec->lanes)
        if (std::abs(n.lateral - lane) < lane_half_m) return false;
    }
  }
  for (const Path& route : routes)
    for (const Eigen::Vector2d& p : pts)
      if (route.nearest(p).distance < lane_half_m) return false;
  return true;
}

World buildWorld(const Scenario& scenario) {
  World w;
  for (const RoadSpec& spec : scenario.roads) w.roads.push_back({&spec, Path::fromRoute(spec.route)});
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(1e300), hi = -lo;
  for (const Road& r : w.roads)
    for (const Path::Sample& s : r.centre.samples()) {
      lo = lo.cwiseMin(s.p - Eigen::Vector2d::Constant(r.spec->clear_m));
      hi = hi.cwiseMax(s.p + Eigen::Vector2d::Constant(r.spec->clear_m));
    }
  w.ground = std::make_unique<Ground>(scenario.ground, streamKey({scenario.seed, 1}), lo, hi);
  for (const Road& r : w.roads) w.ground->paintRoad(r.centre, *r.spec);
  if (scenario.ego.path.route) w.routes.push_back(w.pathOf(scenario.ego.path));
  for (const TrafficSpec& t : scenario.traffic)
    if (t.path.route) w.routes.push_back(w.pathOf(t.path));
  RoadsideBuilder builder(w, streamKey({scenario.seed, 2}), scenario.sensor, streamKey({scenario.seed, 9}));
  for (const Road& r : w.roads) builder.build(r);
  w.grid = std::make_unique<SolidGrid>(builder.solids);
  return w;
}

}  // namespace dlslot::sim
