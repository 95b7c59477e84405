#include "sensor.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <thread>

#include "object_shape.hpp"
#include "rng.hpp"

namespace dlslot::sim {

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

namespace {

// Objects each azimuth column can see: an object's bounding circle in the lidar's xy plane covers
// a range of azimuths, and only rays in those columns are tested against it. The circle is grown
// by how far the object and the lidar move in half a sweep, and the range by `extra` columns
// (the lidar's turn over half a sweep, the beams' azimuth residuals, the firing phase).
std::vector<std::vector<int>> azimuthBuckets(const ScanInput& in, int columns, double max_range, double half_sweep_s,
                                             int extra) {
  std::vector<std::vector<int>> buckets(columns);
  const Pose T_lidar_map = in.T_map_lidar.inverse();
  const double step = 2 * M_PI / columns;
  for (size_t i = 0; i < in.object_boxes.size(); ++i) {
    const Box& b = in.object_boxes[i];
    const Eigen::Vector3d c = T_lidar_map * b.center;
    const double v = in.object_velocity.empty() ? 0.0 : in.object_velocity[i].norm();
    const double radius = 0.5 * b.size.norm() + kPartsOutsideBoxM + 0.05 + half_sweep_s * (v + in.ego.velocity.norm());
    const double rho = c.head<2>().norm();
    if (rho - radius > max_range) continue;
    if (rho <= radius) {
      for (auto& bucket : buckets) bucket.push_back(static_cast<int>(i));
      continue;
    }
    const double centre = std::atan2(c.y(), c.x()), half = std::asin(radius / rho);
    const int first = static_cast<int>(std::floor((centre - half) / step)) - extra;
    const int last = static_cast<int>(std::ceil((centre + half) / step)) + extra;
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

double beamElevationDeg(const SensorSpec& sensor, int beam) {
  if (sensor.beams == kBeams) return beamElevationDeg(beam);
  return sensor.top_elevation_deg -
         beam * (sensor.top_elevation_deg - sensor.bottom_elevation_deg) / (sensor.beams - 1);
}

int aloamBeam(double angle) {
  return angle >= -8.83 ? static_cast<int>((2 - angle) * 3.0 + 0.5)
                        : 32 + static_cast<int>((-8.83 - angle) * 2.0 + 0.5);
}

Scan scan(const SensorSpec& sensor, const ScanInput& in, int threads) {
  const World& world = *in.world;
  const int columns = sensor.azimuth_steps;
  const double phase = azimuthPhase(sensor, in.key);
  // Each column is fired at its own time of the sweep, from where the lidar is then.
  std::vector<double> cos_az(columns), sin_az(columns), fired(columns);
  std::vector<Pose> T_fire(columns);
  double max_t = 0;
  for (int a = 0; a < columns; ++a) {
    const double az = columnAzimuth(sensor, a, phase);
    cos_az[a] = std::cos(az);
    sin_az[a] = std::sin(az);
    fired[a] = firingTime(sensor, az, in.period_s);
    T_fire[a] = in.ego.at(fired[a]);
    max_t = std::max(max_t, std::abs(fired[a]));
  }
  double max_az_error = 0;
  for (const BeamError& e : in.beam_errors) max_az_error = std::max(max_az_error, std::abs(e.azimuth_rad));
  const double step = 2 * M_PI / columns;
  const int extra = 2 + static_cast<int>(std::ceil((in.ego.omega.norm() * max_t + max_az_error) / step));
  const auto buckets = azimuthBuckets(in, columns, sensor.max_range_m, max_t, extra);
  // Object boxes as solids, for the rays-through-box counts; grown by what reaches out of them
  // (mirrors), the rays that may meet the object's parts.
  std::vector<Solid> box_solids, reach_solids;
  const Eigen::Vector3d reach(2 * kPartsOutsideBoxM, 2 * kPartsOutsideBoxM, 0.0);
  for (const Box& b : in.object_boxes) {
    box_solids.push_back(Solid::box(b.center, b.size, b.yaw, 0.0f));
    reach_solids.push_back(Solid::box(b.center, b.size + reach, b.yaw, 0.0f));
  }
  // Each object's parts: indices into object_solids.
  std::vector<std::vector<int>> parts(in.object_boxes.size());
  for (size_t k = 0; k < in.object_solids.size(); ++k) parts[in.object_solids[k].owner].push_back(static_cast<int>(k));
  auto velocityOf = [&](int obj) {
    return in.object_velocity.empty() ? Eigen::Vector3d::Zero().eval() : in.object_velocity[obj];
  };
  const Pose T_ref_map = in.ego.T_ref.inverse();

  const int beams = sensor.beams;
  if (!in.beam_errors.empty() && static_cast<int>(in.beam_errors.size()) != beams)
    throw std::invalid_argument("sim::scan: " + std::to_string(in.beam_errors.size()) + " beam residuals for " +
                                std::to_string(beams) + " beams");
  std::vector<BeamPoints> out(beams);
  threads = std::clamp(threads, 1, beams);
  std::vector<std::vector<ObjectView>> views(threads, std::vector<ObjectView>(in.object_boxes.size()));

  auto work = [&](int thread) {
    SolidGrid::Scratch scratch = world.grid->scratch();
    std::vector<std::pair<int, double>> entered;  // objects whose box this ray enters, and where
    for (int b = thread; b < beams; b += threads) {
      static const BeamError kExact{};  // no residuals given: the rays leave at the nominal angles
      const BeamError& err = in.beam_errors.empty() ? kExact : in.beam_errors[b];
      // The stored point has the beam's nominal elevation; the ray leaves at the true one.
      const double el = beamElevationDeg(sensor, b) * M_PI / 180.0, el_true = el + err.elevation_rad;
      const double ce = std::cos(el), se = std::sin(el);
      const double ce_true = std::cos(el_true), se_true = std::sin(el_true);
      const double ca_err = std::cos(err.azimuth_rad), sa_err = std::sin(err.azimuth_rad);
      BeamPoints& bp = out[b];
      double ground_guess = 0;  // the previous column's ground distance starts the next search
      for (int a = 0; a < columns; ++a) {
        const uint64_t ray_key = streamKey({in.key, static_cast<uint64_t>(b), static_cast<uint64_t>(a)});
        Rng rng(ray_key);
        const double ca = cos_az[a] * ca_err - sin_az[a] * sa_err, sa = sin_az[a] * ca_err + cos_az[a] * sa_err;
        const Eigen::Vector3d dl(ce * cos_az[a], ce * sin_az[a], se);
        const Eigen::Vector3d d = T_fire[a].linear() * Eigen::Vector3d(ce_true * ca, ce_true * sa, se_true);
        const Eigen::Vector3d o = T_fire[a].translation();
        double best = world.ground->intersect(o, d, sensor.max_range_m, ground_guess);
        int32_t solid = -1, object = -1;
        bool hit = std::isfinite(best);
        if (hit) ground_guess = best;
        if (!hit) best = sensor.max_range_m;
        double s;
        const uint64_t porous_key = mix64(ray_key ^ 0x9042u);
        const int k = world.grid->cast(o, d, best, s, scratch, &porous_key);
        if (k >= 0) {
          best = s;
          solid = k;
          hit = true;
        }
        entered.clear();
        for (int obj : buckets[a]) {
          // Objects move during the sweep too: the ray meets the object where it is when fired,
          // i.e. the object at the reference time seen from an origin moved back by its motion.
          const Eigen::Vector3d o_obj = o - fired[a] * velocityOf(obj);
          double e;
          if (!intersect(reach_solids[obj], o_obj, d, sensor.max_range_m, e)) continue;
          if (intersect(box_solids[obj], o_obj, d, sensor.max_range_m, e)) entered.emplace_back(obj, e);
          for (int p : parts[obj])
            if (intersect(in.object_solids[p], o_obj, d, best, s)) {
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
        const Eigen::Vector3d p_surface = object >= 0 ? Eigen::Vector3d(p - fired[a] * velocityOf(object)) : p;
        const Eigen::Vector3d n = solid == -1  ? world.ground->normal(p.head<2>())
                                  : solid >= 0 ? normalAt(world.grid->solids()[solid], p)
                                               : normalAt(in.object_solids[-2 - solid], p_surface);
        const double incidence = std::abs(n.dot(d));
        const float refl = solid == -1  ? groundReflectivity(world.ground->surface(p.head<2>()))
                           : solid >= 0 ? world.grid->solids()[solid].reflectivity
                                        : in.object_solids[-2 - solid].reflectivity;
        // Lost returns: at random, and where the received signal is weak; rays grazing a surface
        // (under 1.7 deg) never come back.
        if (rng.uniform() < dropoutProbability(sensor, best, incidence, refl) || incidence < 0.03) continue;
        double n_range, n_intensity;
        rng.normalPair(n_range, n_intensity);
        const double range = best + err.range_bias_m + rangeSigma(sensor, best, incidence) * n_range;
        // Reflectivity with a Lambertian-like falloff; the gain brings a typical street to KITTI's
        // mean reflectance (about 0.25), bright paint and signs saturate.
        const double intensity = std::clamp(1.6 * refl * (0.4 + 0.6 * incidence) * (1.0 + 0.1 * n_intensity), 0.0, 1.0);
        // Along the nominal beam, in the lidar frame of the firing (as the sensor saw it), or moved
        // into the reference-time frame (de-skewed, as KITTI's odometry scans are).
        Eigen::Vector3d q = range * dl;
        if (sensor.deskewed) q = T_ref_map * (T_fire[a] * q);
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
  for (int b = 0; b < beams; ++b) {
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
