// The real lidar's imperfections, each checked against its own definition in
// sensor_model.hpp: the formulas at known points, their random draws' statistics, and whole
// scans: every point lies on the true ray of its beam, fired at its time of the sweep from where
// the lidar was then, at the surface it names, off by the beam's range bias and noise of the
// modelled sigma; weak returns are lost as often as the model says; foliage and fences let rays in.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "sim/rng.hpp"
#include "sim/simulation.hpp"
#include "sim_scenario.hpp"

using namespace dlslot;

namespace {

constexpr double kDeg = M_PI / 180.0;

Eigen::Vector3d direction(double el, double az) {
  return {std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)};
}

// Where the ray of stored point i was fired from and where it went (map frame), from the model:
// its column's azimuth and firing time, its beam's true angles. For object points the origin is
// moved back by the object's motion (the object's solids are stored at the reference time).
void trueRay(const sim::Simulation& sim, const sim::Simulation::FrameData& fd, Eigen::Index i, Eigen::Vector3d& o,
             Eigen::Vector3d& d, double& fired) {
  const sim::SensorSpec& sensor = sim.scenario().sensor;
  const Eigen::Vector3d q = fd.scan.points.col(i).head<3>().cast<double>();
  const double az = std::atan2(q.y(), q.x());
  const int b = fd.scan.beam[i];
  const sim::BeamError& e = fd.input.beam_errors[b];
  fired = sim::firingTime(sensor, az, fd.input.period_s);
  const Pose T = fd.input.ego.at(fired);
  o = T.translation();
  d = T.linear() * direction(sim::beamElevationDeg(b) * kDeg + e.elevation_rad, az + e.azimuth_rad);
  if (fd.scan.object[i] >= 0) o -= fired * fd.input.object_velocity[fd.scan.object[i]];
}

const sim::Solid* solidOf(const sim::Simulation& sim, const sim::Simulation::FrameData& fd, Eigen::Index i) {
  const int32_t s = fd.scan.solid[i];
  if (s == -1) return nullptr;
  return s >= 0 ? &sim.world().grid->solids()[s] : &fd.input.object_solids[-2 - s];
}

}  // namespace

TEST(SimSensorModel, FormulasAtKnownPoints) {
  sim::SensorSpec s;
  s.range_noise_m = 0.02;
  s.range_noise_per_100m = 0.03;
  s.beam_divergence_mrad = 2.0;
  s.footprint_noise = 0.5;
  EXPECT_NEAR(sim::rangeSigma(s, 50, 1.0), 0.035, 1e-12);  // head-on: no footprint depth
  // 60 deg: tan = sqrt(3); footprint depth 50 * 0.002 * sqrt(3), half of it as sigma
  EXPECT_NEAR(sim::rangeSigma(s, 50, 0.5), std::hypot(0.035, 0.5 * 50 * 0.002 * std::sqrt(3.0)), 1e-12);
  EXPECT_NEAR(sim::rangeSigma(s, 50, 1e-6), std::hypot(0.035, 0.5 * 50 * 0.002 * 10), 1e-12);  // tan capped
  s.dropout = 0.02;
  s.dropout_signal = 0.02;
  s.dropout_steepness = 2;
  // signal = 0.2 * 0.1 * (100/100)^2 = dropout_signal: half of the non-random returns lost
  EXPECT_NEAR(sim::dropoutProbability(s, 100, 0.1, 0.2), 0.02 + 0.98 * 0.5, 1e-12);
  // ten times the signal: 1 / (1 + 10^2)
  EXPECT_NEAR(sim::dropoutProbability(s, 100, 1.0, 0.2), 0.02 + 0.98 / 101, 1e-12);
  s.dropout_signal = 0;
  EXPECT_EQ(sim::dropoutProbability(s, 100, 0.01, 0.01), 0.02);

  // Clockwise spin, reference time facing ahead: left side before it, right side after, behind at +-T/2.
  EXPECT_NEAR(sim::firingTime(s, 0.0, 0.1), 0.0, 1e-15);
  EXPECT_NEAR(sim::firingTime(s, M_PI / 2, 0.1), -0.025, 1e-15);
  EXPECT_NEAR(sim::firingTime(s, -M_PI / 2, 0.1), 0.025, 1e-15);
  EXPECT_NEAR(std::abs(sim::firingTime(s, M_PI, 0.1)), 0.05, 1e-12);
  s.motion_distortion = false;
  EXPECT_EQ(sim::firingTime(s, 1.0, 0.1), 0.0);

  s.azimuth_steps = 2000;
  EXPECT_NEAR(sim::columnAzimuth(s, 500, 0.25), 2 * M_PI * 500.25 / 2000, 1e-15);
}

TEST(SimSensorModel, FiringPhaseChangesFromRevolutionToRevolution) {
  sim::SensorSpec s;
  double sum = 0;
  int distinct = 0;
  double last = -1;
  for (uint64_t k = 0; k < 2000; ++k) {
    const double p = sim::azimuthPhase(s, sim::streamKey({7, k}));
    ASSERT_GE(p, 0.0);
    ASSERT_LT(p, 1.0);
    sum += p;
    distinct += p != last;
    last = p;
  }
  EXPECT_NEAR(sum / 2000, 0.5, 0.02);  // uniform over a column
  EXPECT_EQ(distinct, 2000);
  s.azimuth_phase = false;
  EXPECT_EQ(sim::azimuthPhase(s, 12345), 0.0);

  // In a scan, every point of a ring sits at its column's azimuth with this frame's phase.
  sim::Simulation sim(sim::test::shippedScenario("urban-static", 2));
  const int n = sim.scenario().sensor.azimuth_steps;
  double phases[2];
  for (int k = 0; k < 2; ++k) {
    const auto fd = sim.frame(k, 2);
    phases[k] = sim::azimuthPhase(sim.scenario().sensor, fd.input.key);
    int checked = 0;
    for (Eigen::Index i = 0; i < fd.scan.points.cols(); i += 37) {
      const double col = std::atan2(fd.scan.points(1, i), fd.scan.points(0, i)) / (2 * M_PI) * n;
      double frac = col - std::floor(col) - phases[k];
      frac -= std::round(frac);
      ASSERT_NEAR(frac, 0.0, 2e-3) << "frame " << k << " point " << i;
      ++checked;
    }
    EXPECT_GT(checked, 1000);
  }
  EXPECT_GT(std::abs(phases[0] - phases[1]), 1e-6);
}

TEST(SimSensorModel, BeamResidualsHaveTheConfiguredSpreadAndKittisVerticalError) {
  sim::SensorSpec s;
  s.vertical_angle_error_deg = 0;
  s.beam_elevation_error_deg = 0.05;
  s.beam_azimuth_error_deg = 0.08;
  s.beam_range_bias_m = 0.03;
  double se = 0, sa = 0, sr = 0, me = 0;
  const int sensors = 300;
  for (int k = 0; k < sensors; ++k)
    for (const sim::BeamError& e : sim::beamErrors(s, sim::streamKey({3, static_cast<uint64_t>(k)}))) {
      se += e.elevation_rad * e.elevation_rad;
      sa += e.azimuth_rad * e.azimuth_rad;
      sr += e.range_bias_m * e.range_bias_m;
      me += e.elevation_rad;
    }
  const double n = 64.0 * sensors;
  EXPECT_NEAR(std::sqrt(se / n) / kDeg, 0.05, 0.05 * 0.03);
  EXPECT_NEAR(std::sqrt(sa / n) / kDeg, 0.08, 0.08 * 0.03);
  EXPECT_NEAR(std::sqrt(sr / n), 0.03, 0.03 * 0.03);
  EXPECT_NEAR(me / n / kDeg, 0.0, 0.002);
  // The same key gives the same sensor; KITTI's error raises every beam by 0.22 deg.
  const auto a = sim::beamErrors(s, 99);
  s.vertical_angle_error_deg = 0.22;
  const auto b = sim::beamErrors(s, 99);
  for (int i = 0; i < 64; ++i) {
    EXPECT_NEAR(b[i].elevation_rad - a[i].elevation_rad, 0.22 * kDeg, 1e-15);
    EXPECT_EQ(b[i].azimuth_rad, a[i].azimuth_rad);
  }
}

TEST(SimSensorModel, SweepMotionInterpolatesTheNeighbouringPoses) {
  Pose a = Pose::Identity(), b = Pose::Identity(), c = Pose::Identity();
  b.translation() = Eigen::Vector3d(1.0, 0.1, 0.0);
  b.linear() = Eigen::AngleAxisd(0.02, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  c.translation() = Eigen::Vector3d(2.0, 0.2, 0.0);
  c.linear() = Eigen::AngleAxisd(0.04, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const sim::SweepMotion m = sim::sweepMotion(&a, b, &c, 0.1);
  EXPECT_TRUE(m.velocity.isApprox(Eigen::Vector3d(10, 1, 0), 1e-12));
  EXPECT_TRUE(m.omega.isApprox(Eigen::Vector3d(0, 0, 0.2), 1e-12));
  EXPECT_TRUE(m.at(0).isApprox(b, 1e-12));
  EXPECT_TRUE(m.at(0.1).isApprox(c, 1e-12));   // constant twist reaches the next pose
  EXPECT_TRUE(m.at(-0.1).isApprox(a, 1e-12));
  const sim::SweepMotion end = sim::sweepMotion(&b, c, nullptr, 0.1);  // one-sided at the last frame
  EXPECT_TRUE(end.at(-0.1).isApprox(b, 1e-12));
}

TEST(SimSensorModel, PorousSolidsStopRaysAtAnExponentialDepth) {
  // A wire fence 5 cm thick passing 40 % of square-on rays.
  sim::Solid fence = sim::Solid::box(Eigen::Vector3d(10, 0, 1), Eigen::Vector3d(0.05, 4, 2), 0.0, 0.4f);
  fence.mean_free_path = static_cast<float>(-0.05 / std::log(0.4));
  const Eigen::Vector3d o(0, 0, 1), d(1, 0, 0);
  int passed = 0;
  const int n = 20000;
  for (int k = 0; k < n; ++k) {
    double s;
    const double u = (k + 0.5) / n;
    if (!sim::intersectPorous(fence, o, d, 100, u, s)) {
      ++passed;
      continue;
    }
    ASSERT_GE(s, 9.975 - 1e-9);
    ASSERT_LE(s, 10.025 + 1e-9);
    ASSERT_NEAR(s, 9.975 - fence.mean_free_path * std::log(1 - u), 1e-9);
  }
  EXPECT_NEAR(passed / double(n), 0.4, 1e-3);
  // A deep crown: the mean depth of the hits is the mean free path (the chord, 6 m, is 10 of them).
  sim::Solid crown = sim::Solid::sphere(Eigen::Vector3d(20, 0, 1), 3.0, 0.12f);
  crown.mean_free_path = 0.6f;
  double depth = 0;
  int hits = 0;
  for (int k = 0; k < n; ++k) {
    double s;
    if (sim::intersectPorous(crown, o, d, 100, (k + 0.5) / n, s)) {
      depth += s - 17.0;
      ++hits;
    }
  }
  EXPECT_NEAR(hits / double(n), 1 - std::exp(-6.0 / 0.6), 1e-3);
  EXPECT_NEAR(depth / hits, 0.6, 0.01);
  // The shipped street has porous crowns (spheres) and wire fences (thin boxes); switched off, none.
  for (const bool on : {true, false}) {
    sim::Scenario sc = sim::test::shippedScenario("urban-static", 1);
    if (!on) sc.sensor.vegetation_mean_free_path_m = sc.sensor.fences = 0;
    sim::Simulation sim(sc);
    int crowns = 0, fences = 0;
    for (const sim::Solid& solid : sim.world().grid->solids()) {
      if (solid.mean_free_path <= 0) continue;
      crowns += solid.kind == sim::SolidKind::Sphere;
      fences += solid.kind == sim::SolidKind::Box && solid.half.y() < 0.05;
    }
    EXPECT_EQ(crowns > 10, on);
    EXPECT_EQ(fences > 3, on);
  }
  crown.mean_free_path = 0;  // opaque: the surface
  double s;
  ASSERT_TRUE(sim::intersectPorous(crown, o, d, 100, 0.9, s));
  EXPECT_NEAR(s, 17.0, 1e-12);
}

// The whole chain on real scans of urban-static, every default on: each point is its beam's true
// ray, fired at its column's time from where the lidar (and the object it hit) was then, to the
// surface it names, plus the beam's range bias and noise whose normalized spread is 1.
TEST(SimSensorModel, PointsLieOnTheirTrueRaysWithTheModelledNoise) {
  sim::Simulation sim(sim::test::shippedScenario("urban-static", 2));
  const sim::SensorSpec& sensor = sim.scenario().sensor;
  ASSERT_TRUE(sensor.motion_distortion);
  ASSERT_FALSE(sensor.deskewed);
  double sum2 = 0, sum = 0, sum2_nominal = 0, sum2_structure = 0;
  long n = 0, porous = 0, objects = 0;
  for (int k = 0; k < 2; ++k) {
    const auto fd = sim.frame(k, 2);
    EXPECT_GT(fd.input.ego.velocity.norm(), 3.0);  // the ego moves: the distortion is real
    for (Eigen::Index i = 0; i < fd.scan.points.cols(); ++i) {
      Eigen::Vector3d o, d;
      double fired;
      trueRay(sim, fd, i, o, d, fired);
      const sim::Solid* solid = solidOf(sim, fd, i);
      const double stored = fd.scan.points.col(i).head<3>().cast<double>().norm();
      const double bias = fd.input.beam_errors[fd.scan.beam[i]].range_bias_m;
      double r;
      if (solid && solid->mean_free_path > 0) {  // inside foliage or a fence: between entry and exit
        double s_in, s_out;
        ASSERT_TRUE(sim::chord(*solid, o, d, s_in, s_out)) << "point " << i;
        const double sigma = sim::rangeSigma(sensor, stored, 0.0);
        EXPECT_GT(stored - bias, s_in - 6 * sigma) << "point " << i;
        EXPECT_LT(stored - bias, s_out + 6 * sigma) << "point " << i;
        ++porous;
        continue;
      }
      if (!solid)
        r = sim.world().ground->intersect(o, d, 1e3);
      else
        ASSERT_TRUE(sim::intersect(*solid, o, d, 1e3, r)) << "point " << i << " misses the solid it names";
      ASSERT_TRUE(std::isfinite(r)) << "point " << i;
      const Eigen::Vector3d p = o + r * d;
      const Eigen::Vector3d nrm = !solid ? sim.world().ground->normal(p.head<2>()) : sim::normalAt(*solid, p);
      const double z = (stored - bias - r) / sim::rangeSigma(sensor, r, std::abs(nrm.dot(d)));
      sum += z;
      sum2 += z * z;
      ++n;
      objects += fd.scan.object[i] >= 0;
      // A structure point against its nominal ray from the reference pose: ignoring the motion
      // and the calibration would not explain it.
      const Eigen::Vector3d q = fd.scan.points.col(i).head<3>().cast<double>();
      double r0;
      if (fd.scan.solid[i] >= 0 && sim::intersect(*solid, fd.input.T_map_lidar.translation(),
                                                  fd.input.T_map_lidar.linear() * q.normalized(), 1e3, r0)) {
        const double z0 = (stored - r0) / sim::rangeSigma(sensor, r, std::abs(nrm.dot(d)));
        sum2_nominal += z0 * z0;
        sum2_structure += z * z;
      }
    }
  }
  ASSERT_GT(n, 100000);
  EXPECT_GT(objects, 500);
  EXPECT_GT(porous, 200);  // urban-static has trees: some rays end inside crowns
  EXPECT_NEAR(sum / n, 0.0, 0.02);
  EXPECT_NEAR(std::sqrt(sum2 / n), 1.0, 0.03);
  EXPECT_GT(sum2_nominal, 4 * sum2_structure);  // ignoring the motion and calibration would not explain the scan
}

// With `deskewed`, the same rays are written in the reference-time frame: mapped with the
// reference pose, a noise-free point is where its ray hit.
TEST(SimSensorModel, DeskewedScansPutEachPointWhereItsRayHit) {
  for (const bool deskewed : {false, true}) {
    sim::Scenario sc = sim::test::shippedScenario("urban-static", 2);  // two frames: the ego's motion through frame 0
    sc.sensor.deskewed = deskewed;
    sc.sensor.range_noise_m = sc.sensor.range_noise_per_100m = sc.sensor.footprint_noise = 0;
    sc.sensor.beam_range_bias_m = 0;
    sc.sensor.vegetation_mean_free_path_m = 0;
    sim::Simulation sim(sc);
    const auto fd = sim.frame(0, 2);
    double worst = 0, worst_ref = 0;
    for (Eigen::Index i = 0; i < fd.scan.points.cols(); i += 7) {
      if (fd.scan.object[i] >= 0) continue;
      const Eigen::Vector3d q = fd.scan.points.col(i).head<3>().cast<double>();
      // The firing pose from the point's azimuth in the frame it was written in.
      Eigen::Vector3d q_fire = q;
      double fired = sim::firingTime(sc.sensor, std::atan2(q.y(), q.x()), fd.input.period_s);
      if (deskewed) {  // back into the firing frame: iterate the time (it depends on the azimuth seen then)
        for (int it = 0; it < 3; ++it) {
          q_fire = fd.input.ego.at(fired).inverse() * (fd.input.T_map_lidar * q);
          fired = sim::firingTime(sc.sensor, std::atan2(q_fire.y(), q_fire.x()), fd.input.period_s);
        }
      }
      const Eigen::Vector3d hit = fd.input.ego.at(fired) * q_fire;
      const Eigen::Vector3d mapped = (deskewed ? fd.input.T_map_lidar : fd.input.ego.at(fired)) * q;
      worst = std::max(worst, (mapped - hit).norm());
      worst_ref = std::max(worst_ref, (fd.input.T_map_lidar * q - hit).norm());
    }
    EXPECT_LT(worst, 2e-3) << "deskewed " << deskewed;
    if (deskewed)
      EXPECT_LT(worst_ref, 2e-3);
    else
      EXPECT_GT(worst_ref, 0.2);  // as seen: up to half a sweep of ego motion off in the reference frame
  }
}

// Weak returns: of the returns a lossless sensor gets on the ground, the kept share in each
// range band is the model's mean keep probability there (binomial, within 4 sigma).
TEST(SimSensorModel, WeakReturnsAreLostAsTheModelSays) {
  sim::Scenario lossless = sim::test::shippedScenario("urban-static", 1), lossy = lossless;
  lossless.sensor.dropout = 0;
  lossless.sensor.dropout_signal = 0;
  lossy.sensor.dropout = 0.02;
  lossy.sensor.dropout_signal = 0.05;  // stronger than the default, so the far ground thins out
  sim::Simulation a(lossless), b(lossy);
  const auto fa = a.frame(0, 2), fb = b.frame(0, 2);
  const double bands[] = {0, 15, 30, 50, 200};
  for (int band = 0; band < 4; ++band) {
    double expected = 0, var = 0;
    long kept = 0, total = 0;
    for (Eigen::Index i = 0; i < fa.scan.points.cols(); ++i) {
      if (fa.scan.solid[i] != -1) continue;
      Eigen::Vector3d o, d;
      double fired;
      trueRay(a, fa, i, o, d, fired);
      const double r = a.world().ground->intersect(o, d, 1e3);
      if (!(r >= bands[band] && r < bands[band + 1])) continue;
      const Eigen::Vector3d p = o + r * d;
      const double cos_inc = std::abs(a.world().ground->normal(p.head<2>()).dot(d));
      const double rf = sim::groundReflectivity(a.world().ground->surface(p.head<2>()));
      const double keep = 1 - sim::dropoutProbability(lossy.sensor, r, cos_inc, rf);
      expected += keep;
      var += keep * (1 - keep);
      ++total;
    }
    for (Eigen::Index i = 0; i < fb.scan.points.cols(); ++i) {
      if (fb.scan.solid[i] != -1) continue;
      const double r = fb.scan.points.col(i).head<3>().cast<double>().norm();  // within noise of the true range
      kept += r >= bands[band] && r < bands[band + 1];
    }
    ASSERT_GT(total, 200) << "band " << band;
    EXPECT_NEAR(kept, expected, 4 * std::sqrt(var) + 0.01 * total) << "band " << bands[band] << "-" << bands[band + 1];
  }
}
