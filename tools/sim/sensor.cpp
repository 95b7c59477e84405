#include "sensor.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <thread>

#include "rng.hpp"

namespace dlslot::sim {
namespace {

float groundReflectivity(Surface s) {
  switch (s) {
    case Surface::Asphalt:
      return 0.12f;
    case Surface::Sidewalk:
      return 0.28f;
    case Surface::Paint:
      return 0.6f;
    case Surface::Grass:
      return 0.2f;
  }
  return 0.2f;
}

// Objects each azimuth column can see: an object's bounding circle in the lidar's xy plane covers
// a range of azimuths, and only rays in those columns are tested against it.
std::vector<std::vector<int>> azimuthBuckets(const ScanInput& in, int columns, double max_range) {
  std::vector<std::vector<int>> buckets(columns);
  const Pose T_lidar_map = in.T_map_lidar.inverse();
  const double step = 2 * M_PI / columns;
  for (size_t i = 0; i < in.object_boxes.size(); ++i) {
    const Box& b = in.object_boxes[i];
    const Eigen::Vector3d c = T_lidar_map * b.center;
    const double radius = 0.5 * b.size.norm() + 0.05, rho = c.head<2>().norm();
    if (rho - radius > max_range) continue;
    if (rho <= radius) {
      for (auto& bucket : buckets) bucket.push_back(static_cast<int>(i));
      continue;
    }
    const double centre = std::atan2(c.y(), c.x()), half = std::asin(radius / rho);
    const int first = static_cast<int>(std::floor((centre - half) / step));
    const int last = static_cast<int>(std::ceil((centre + half) / step));
    for (int k = first; k <= last; ++k) buckets[((k % columns) + columns) % columns].push_back(static_cast<int>(i));
  }
  return buckets;
}

struct BeamPoints {
  std::vector<float> xyzi;
  std::vector<int32_t> object, solid;
};

}  // namespace

double beamElevationDeg(int beam) {
  // The extreme beams sit 1e-4 deg inside A-LOAM's accepted range [-24.33, 2], so float rounding of
  // the stored points never pushes them out of it.
  if (beam == 0) return 2.0 - 1e-4;
  if (beam == kBeams - 1) return -24.33 + 1e-4;
  return beam < 32 ? 2.0 - beam / 3.0 : -8.83 - 0.5 * (beam - 32);
}

int aloamBeam(double angle) {
  return angle >= -8.83 ? static_cast<int>((2 - angle) * 3.0 + 0.5)
                        : 32 + static_cast<int>((-8.83 - angle) * 2.0 + 0.5);
}

Scan scan(const SensorSpec& sensor, const ScanInput& in, int threads) {
  const World& world = *in.world;
  const int columns = sensor.azimuth_steps;
  const auto buckets = azimuthBuckets(in, columns, sensor.max_range_m);
  // Object boxes as solids, for the rays-through-box counts.
  std::vector<Solid> box_solids;
  for (const Box& b : in.object_boxes) box_solids.push_back(Solid::box(b.center, b.size, b.yaw, 0.0f));
  // Each object's parts: indices into object_solids.
  std::vector<std::vector<int>> parts(in.object_boxes.size());
  for (size_t k = 0; k < in.object_solids.size(); ++k) parts[in.object_solids[k].owner].push_back(static_cast<int>(k));

  std::vector<double> cos_az(columns), sin_az(columns);
  for (int a = 0; a < columns; ++a) {
    cos_az[a] = std::cos(2 * M_PI * a / columns);
    sin_az[a] = std::sin(2 * M_PI * a / columns);
  }
  const Eigen::Matrix3d R = in.T_map_lidar.linear();
  const Eigen::Vector3d o = in.T_map_lidar.translation();
  std::vector<BeamPoints> out(kBeams);
  threads = std::clamp(threads, 1, kBeams);
  std::vector<std::vector<ObjectView>> views(threads, std::vector<ObjectView>(in.object_boxes.size()));

  auto work = [&](int thread) {
    SolidGrid::Scratch scratch = world.grid->scratch();
    std::vector<std::pair<int, double>> entered;  // objects whose box this ray enters, and where
    for (int b = thread; b < kBeams; b += threads) {
      const double el = beamElevationDeg(b) * M_PI / 180.0;
      const double ce = std::cos(el), se = std::sin(el);
      BeamPoints& bp = out[b];
      double ground_guess = 0;  // the previous column's ground distance starts the next search
      for (int a = 0; a < columns; ++a) {
        Rng rng(streamKey({in.key, static_cast<uint64_t>(b), static_cast<uint64_t>(a)}));
        const Eigen::Vector3d dl(ce * cos_az[a], ce * sin_az[a], se);
        const Eigen::Vector3d d = R * dl;
        double best = world.ground->intersect(o, d, sensor.max_range_m, ground_guess);
        int32_t solid = -1, object = -1;
        bool hit = std::isfinite(best);
        if (hit) ground_guess = best;
        if (!hit) best = sensor.max_range_m;
        double s;
        const int k = world.grid->cast(o, d, best, s, scratch);
        if (k >= 0) {
          best = s;
          solid = k;
          hit = true;
        }
        entered.clear();
        for (int obj : buckets[a]) {
          double e;
          if (!intersect(box_solids[obj], o, d, sensor.max_range_m, e)) continue;
          entered.emplace_back(obj, e);
          for (int p : parts[obj])
            if (intersect(in.object_solids[p], o, d, best, s)) {
              best = s;
              solid = -2 - p;
              object = obj;
              hit = true;
            }
        }
        for (const auto& [obj, e] : entered) {
          if (solid == -1 && best < e) continue;  // the ground comes first: the box is not in sight
          ObjectView& v = views[thread][obj];
          ++v.rays;
          if (object != obj && best < e - 0.05) ++v.blocked;
        }
        if (!hit || best < sensor.min_range_m) continue;
        const Eigen::Vector3d p = o + best * d;
        const Eigen::Vector3d n = solid == -1  ? world.ground->normal(p.head<2>())
                                  : solid >= 0 ? normalAt(world.grid->solids()[solid], p)
                                               : normalAt(in.object_solids[-2 - solid], p);
        const double incidence = std::abs(n.dot(d));
        const float refl = solid == -1  ? groundReflectivity(world.ground->surface(p.head<2>()))
                           : solid >= 0 ? world.grid->solids()[solid].reflectivity
                                        : in.object_solids[-2 - solid].reflectivity;
        // Dropouts: random, more for dark surfaces far away, and at grazing incidence.
        const double far = best / sensor.max_range_m;
        const double drop = sensor.dropout + 0.5 * (1.0 - refl) * far * far * far * far;
        if (rng.uniform() < drop || incidence < 0.03) continue;
        double n_range, n_intensity;
        rng.normalPair(n_range, n_intensity);
        const double range = best + sensor.range_noise_m * n_range;
        // Reflectivity with a Lambertian-like falloff; the gain brings a typical street to KITTI's
        // mean reflectance (about 0.25), bright paint and signs saturate.
        const double intensity = std::clamp(1.6 * refl * (0.4 + 0.6 * incidence) * (1.0 + 0.1 * n_intensity), 0.0, 1.0);
        const Eigen::Vector3d q = range * dl;  // along the beam: the elevation stays the beam's
        bp.xyzi.insert(bp.xyzi.end(), {static_cast<float>(q.x()), static_cast<float>(q.y()), static_cast<float>(q.z()),
                                       static_cast<float>(intensity)});
        bp.object.push_back(object);
        bp.solid.push_back(solid);
      }
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work, t);
  work(0);
  for (auto& t : pool) t.join();

  Scan result;
  size_t total = 0;
  for (const BeamPoints& bp : out) total += bp.object.size();
  result.points.resize(4, static_cast<Eigen::Index>(total));
  size_t at = 0;
  for (int b = 0; b < kBeams; ++b) {
    const BeamPoints& bp = out[b];
    std::copy(bp.xyzi.begin(), bp.xyzi.end(), result.points.data() + 4 * at);
    result.beam.insert(result.beam.end(), bp.object.size(), static_cast<uint8_t>(b));
    result.object.insert(result.object.end(), bp.object.begin(), bp.object.end());
    result.solid.insert(result.solid.end(), bp.solid.begin(), bp.solid.end());
    at += bp.object.size();
  }
  result.views.assign(in.object_boxes.size(), {});
  for (const auto& tv : views)
    for (size_t i = 0; i < tv.size(); ++i) {
      result.views[i].rays += tv[i].rays;
      result.views[i].blocked += tv[i].blocked;
    }
  for (int32_t obj : result.object)
    if (obj >= 0) ++result.views[obj].points;
  return result;
}

}  // namespace dlslot::sim
