// The simulated lidar: points lie on the surfaces they came from (range residuals are the range
// noise), the spatial index finds the same nearest surface as testing every solid, A-LOAM's
// scanRegistration recovers the beam of >= 99 % of the points from their elevation, and every
// labelled object's box holds its points (but for its mirrors').
#include <gtest/gtest.h>

#include <cmath>

#include "dlslot/kitti.hpp"
#include "sim/object_shape.hpp"
#include "sim/rng.hpp"
#include "sim/simulation.hpp"
#include "sim_scenario.hpp"

using namespace dlslot;

namespace {

// The ideal lidar: these tests check the ray caster's geometry; the imperfections
// are checked in sim_sensor_model_test.cpp.
sim::Scenario scenario(const std::string& name, int frames) {
  sim::Scenario sc = sim::test::shippedScenario(name, frames);
  sc.sensor = sim::idealSensor(sc.sensor);
  return sc;
}

// The noise-free range of the point's beam to the surface the simulator says it hit.
double trueRange(const sim::Simulation::FrameData& fd, const sim::World& world, size_t i, Eigen::Vector3d& dir_map) {
  const Eigen::Vector3d dir = fd.scan.points.col(i).head<3>().cast<double>().normalized();
  dir_map = fd.input.T_map_lidar.linear() * dir;
  const Eigen::Vector3d o = fd.input.T_map_lidar.translation();
  const int32_t solid = fd.scan.solid[i];
  if (solid == -1) return world.ground->intersect(o, dir_map, 1e3);
  const sim::Solid& s = solid >= 0 ? world.grid->solids()[solid] : fd.input.object_solids[-2 - solid];
  double r = NAN;
  if (!sim::intersect(s, o, dir_map, 1e3, r)) return NAN;
  return r;
}

}  // namespace

TEST(SimScan, PointsLieOnTheirSurfacesWithinTheRangeNoise) {
  for (const std::string name : {"urban-static", "intersection"}) {
    sim::Simulation sim(scenario(name, 2));
    const double sigma = sim.scenario().sensor.range_noise_m;
    for (int k = 0; k < 2; ++k) {
      const auto fd = sim.frame(k, 2);
      ASSERT_GT(fd.scan.points.cols(), 60000) << name;
      double sum2 = 0;
      int n = 0, outliers = 0, by_kind[3] = {0, 0, 0};
      for (Eigen::Index i = 0; i < fd.scan.points.cols(); ++i) {
        Eigen::Vector3d d;
        const double r = trueRange(fd, sim.world(), i, d);
        ASSERT_TRUE(std::isfinite(r)) << name << " point " << i << " does not lie on the surface it names";
        const double res = fd.scan.points.col(i).head<3>().cast<double>().norm() - r;
        sum2 += res * res;
        ++n;
        outliers += std::abs(res) > 5 * sigma;
        ++by_kind[fd.scan.solid[i] == -1 ? 0 : fd.scan.solid[i] >= 0 ? 1 : 2];
      }
      EXPECT_NEAR(std::sqrt(sum2 / n), sigma, 0.1 * sigma) << name;
      EXPECT_LT(outliers, n / 10000 + 1) << name;
      EXPECT_GT(by_kind[0], n / 5) << name << ": ground";
      EXPECT_GT(by_kind[1], n / 20) << name << ": structure";
      EXPECT_GT(by_kind[2], 500) << name << ": objects";
    }
  }
}

TEST(SimScan, SpatialIndexFindsTheNearestSolidLikeBruteForce) {
  sim::Simulation sim(scenario("urban-static", 1));
  const sim::World& w = sim.world();
  const auto& solids = w.grid->solids();
  ASSERT_GT(solids.size(), 300u);
  const Pose T = sim.motion().ego[0];
  sim::SolidGrid::Scratch scratch = w.grid->scratch();
  sim::Rng rng(42);
  int hits = 0;
  for (int k = 0; k < 20000; ++k) {
    const double az = rng.uniform(-M_PI, M_PI), el = rng.uniform(-0.45, 0.3);
    const Eigen::Vector3d d =
        T.linear() * Eigen::Vector3d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
    const Eigen::Vector3d o = T.translation() + Eigen::Vector3d(rng.uniform(-20, 20), rng.uniform(-3, 3), 0);
    double s_grid = 0;
    const int i_grid = w.grid->cast(o, d, 120.0, s_grid, scratch);
    int i_brute = -1;
    double s_brute = 120.0;
    for (size_t i = 0; i < solids.size(); ++i) {
      double s;
      if (sim::intersect(solids[i], o, d, s_brute, s)) {
        s_brute = s;
        i_brute = static_cast<int>(i);
      }
    }
    ASSERT_EQ(i_grid >= 0, i_brute >= 0) << "ray " << k;
    if (i_grid >= 0) {
      ++hits;
      EXPECT_NEAR(s_grid, s_brute, 1e-9) << "ray " << k;
    }
  }
  EXPECT_GT(hits, 5000);
}

TEST(SimScan, BeamsAreRecoveredFromTheElevationLikeALoam) {
  for (int b = 0; b < sim::kBeams; ++b) EXPECT_EQ(sim::aloamBeam(sim::beamElevationDeg(b)), b);
  EXPECT_NEAR(sim::beamElevationDeg(0), 2.0, 1e-3);
  EXPECT_NEAR(sim::beamElevationDeg(31), -8.333, 1e-3);
  EXPECT_NEAR(sim::beamElevationDeg(32), -8.83, 1e-9);
  EXPECT_NEAR(sim::beamElevationDeg(63), -24.33, 1e-3);
  sim::Simulation sim(scenario("highway", 1));
  const auto fd = sim.frame(0, 2);
  // As A-LOAM computes it: from the float point, in degrees.
  long right = 0, in_range = 0;
  const long n = fd.scan.points.cols();
  for (long i = 0; i < n; ++i) {
    const float x = fd.scan.points(0, i), y = fd.scan.points(1, i), z = fd.scan.points(2, i);
    const float angle = std::atan(z / std::sqrt(x * x + y * y)) * 180 / float(M_PI);
    right += sim::aloamBeam(angle) == fd.scan.beam[i];
    in_range += angle <= 2 && angle >= -24.33f;  // A-LOAM drops points outside
  }
  EXPECT_GE(right, 0.99 * n);
  EXPECT_EQ(in_range, n);
  // Points come ring by ring from the top beam, like a KITTI scan.
  EXPECT_TRUE(std::is_sorted(fd.scan.beam.begin(), fd.scan.beam.end()));
}

TEST(SimScan, EveryLabelledBoxHoldsItsPoints) {
  for (const std::string name : {"intersection", "parking-lot"}) {
    sim::Simulation sim(scenario(name, 3));
    int labelled = 0, dontcare = 0, outside = 0, tyre = 0;
    for (int k = 0; k < 3; ++k) {
      const auto fd = sim.frame(k, 2);
      for (const kitti::LabelRow& r : fd.labels) {
        const Box b = kitti::cameraToLidar(r.box, sim.calib());
        int inside = 0;
        for (Eigen::Index i = 0; i < fd.scan.points.cols(); ++i)
          inside += b.contains(fd.scan.points.col(i).head<3>().cast<double>(), 0.1);
        if (r.type == "DontCare") {
          ++dontcare;
          EXPECT_EQ(r.track_id, -1);
          EXPECT_GT(r.box.h, 0);  // DontCare rows keep their 3D box
          continue;
        }
        ++labelled;
        EXPECT_GE(inside, sim.scenario().labels.min_points) << name << " frame " << k << " track " << r.track_id;
        EXPECT_GE(r.track_id, 0);
        EXPECT_GE(r.occluded, 0);
        EXPECT_LE(r.occluded, 2);
      }
      // Points the simulator attributes to an object lie in that object's box, but for its
      // mirrors' (KITTI's boxes leave them out); some come from tyres.
      const Pose T_lidar_map = fd.input.T_map_lidar.inverse();
      for (Eigen::Index i = 0; i < fd.scan.points.cols(); ++i) {
        if (fd.scan.object[i] < 0) continue;
        const Box b = fd.input.object_boxes[fd.scan.object[i]].transformed(T_lidar_map);
        const Eigen::Vector3d p = fd.scan.points.col(i).head<3>().cast<double>();
        ASSERT_TRUE(b.contains(p, sim::kPartsOutsideBoxM + 1e-6)) << name << " point " << i;
        outside += !b.contains(p, 1e-6);
        tyre += fd.input.object_solids[-2 - fd.scan.solid[i]].kind == sim::SolidKind::Wheel;
      }
    }
    EXPECT_GT(labelled, 20) << name;
    EXPECT_GT(dontcare, 0) << name;
    EXPECT_GT(outside, 0) << name << ": mirrors";
    EXPECT_GT(tyre, 0) << name << ": tyres";
  }
}
