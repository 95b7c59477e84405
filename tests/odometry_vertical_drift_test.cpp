// The odometry's pitch drift on a simulated street of buildings, walls and poles, seen by an
// otherwise ideal lidar with KITTI's vertical-angle error (each point stored 0.22 deg below its
// ray), on flat ground with a rigid ride: any height the odometry gains or loses is its own. As
// A-LOAM registers such scans (the points as stored, every edge) it loses about a metre of height
// over 150 m; with the points put back on their rays (lidar_odometry.cpp) and only near-vertical
// edges matched (scan_to_map.cpp) it keeps its height to centimetres.
#include <gtest/gtest.h>

#include <cmath>

#include "odometry/lidar_odometry.hpp"
#include "sim/sensor_model.hpp"
#include "sim/simulation.hpp"
#include "sim_scenario.hpp"

namespace dlslot::odometry {
namespace {

struct Drift {
  double height_m = 0;   // estimate - truth, at the last frame
  double pitch_deg = 0;  // the estimate's nose-up tilt against the truth's, at the last frame
};

Drift driftAtEnd(const Pose& estimate, const Pose& truth) {
  const Eigen::Matrix3d R = estimate.linear() * truth.linear().transpose();  // world-frame tilt
  // The street runs along the world's x: a nose-up tilt turns x towards z (about -y).
  return {estimate.translation().z() - truth.translation().z(), -std::asin(R(0, 2)) * 180.0 / M_PI};
}

TEST(OdometryVerticalDrift, KittisLidarKeepsItsHeightOnceItsPointsAreBackOnTheirRays) {
  sim::Scenario sc = sim::test::shippedScenario("urban-loop", 150);  // 150 m of its first straight
  sc.traffic.clear();
  for (sim::RoadSpec& road : sc.roads) {
    road.parking.reset();
    road.roadside.trees_every_m = road.roadside.bushes_every_m = 0.0;
  }
  sc.sensor = sim::idealSensor(sc.sensor);
  sc.sensor.vertical_angle_error_deg = 0.22;
  sc.ground.max_slope = 0.0;
  sc.ego.body_pitch_roll = 0.0;
  sc.ego.body_heave_m = 0.0;
  sim::Simulation sim(sc);
  const std::vector<Pose> truth = sim.lidarPoses();

  OdometryConfig as_fired;  // A-LOAM: the points as stored, every edge
  OdometryConfig on_rays = as_fired;  // the points put back on their rays, every edge
  on_rays.vertical_angle_error_rad = 0.22 * M_PI / 180.0;
  OdometryConfig corrected = on_rays;  // ... and only near-vertical edges (the shipped settings)
  corrected.scan_to_map.edge_max_tilt_deg = 45.0;
  LidarOdometry a(as_fired), r(on_rays), b(corrected);
  Pose last_a, last_r, last_b;
  for (int f = 0; f < sc.frames; ++f) {
    Frame frame;
    frame.index = f;
    frame.scan = sim.frame(f, 2).scan.points;
    last_a = a.process(frame, false).T_world_lidar;
    last_r = r.process(frame, false).T_world_lidar;
    last_b = b.process(frame, false).T_world_lidar;
  }
  const Drift da = driftAtEnd(last_a, truth.back()), dr = driftAtEnd(last_r, truth.back()),
              db = driftAtEnd(last_b, truth.back());
  std::printf("after %.0f m: as stored %+.3f m, %+.3f deg; on their rays %+.3f m, %+.3f deg; and vertical edges %+.3f m, %+.3f deg\n",
              truth.back().translation().norm(), da.height_m, da.pitch_deg, dr.height_m, dr.pitch_deg, db.height_m,
              db.pitch_deg);
  // As stored, each scan's ground is a cone 0.0038 x range too low: registered from places
  // metres apart, the cones tilt the nose down a little every scan.
  EXPECT_LT(da.height_m, -0.5);
  EXPECT_LT(da.pitch_deg, -0.1);
  EXPECT_LT(std::abs(db.height_m), 0.15);
  EXPECT_LT(std::abs(db.pitch_deg), 0.1);
  EXPECT_LT(std::abs(db.height_m), std::abs(da.height_m) / 4);
  // On their rays but with every edge, the ring's crossings of horizontal corners, which move with
  // the viewpoint, tilt it the other way.
  EXPECT_LT(std::abs(db.pitch_deg), std::abs(dr.pitch_deg));
}

}  // namespace
}  // namespace dlslot::odometry
