// One car in a synthetic scene (backend_scene.hpp) whose points are scanned each frame
// (object_scan.hpp): for the backend tests of what a vehicle's own points measure.
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <random>
#include <utility>

#include "backend/backend_config.hpp"
#include "backend/sliding_window.hpp"
#include "backend_scene.hpp"
#include "object_scan.hpp"

namespace dlslot::backend::test {

// One car (id 1, kCar) on `pose`, its boxes box_noise off (x, y; 0.05 m in z), seen by an ego at
// the origin unless the scene is told otherwise.
inline SimScene oneCar(std::function<Pose(double)> pose, double box_noise) {
  SimScene scene;
  SimObject car;
  car.id = 1;
  car.type = "Car";
  car.size = kCar;
  car.pose = std::move(pose);
  car.dynamic_guess = true;
  scene.objects = {car};
  scene.box_noise = Eigen::Vector3d(box_noise, box_noise, 0.05);
  return scene;
}

// The car's points in this frame's scan (lidar frame), given to its observation; column_phase as
// scanBox's.
inline void scanTheCar(const SimScene& scene, BackendInput& in, std::mt19937& rng, double column_phase = -1.0) {
  const Pose car_in_lidar = scene.egoTruth(in.frame).inverse() * scene.objectTruth(1, in.frame);
  for (ObservationInput& o : in.observations)
    o.points = std::make_shared<const ObjectPoints>(
        scanBox(car_in_lidar, kCar, Eigen::Vector3d::Zero(), rng, 0.01, false, 0.3, column_phase));
}

// The car's published velocities against `truth` (world x-y) from frame first_frame on, over the
// scene's first `frames` frames, its points scanned each frame (with the columns shifted anew each
// scan when shift_columns, as a lidar's firing phase does): their RMS error and how many there were.
struct VelocityErrors {
  double rmse = 0;
  int count = 0;
};
inline VelocityErrors publishedVelocityErrors(const SimScene& scene, const BackendConfig& config, int frames,
                                              int first_frame, const Eigen::Vector2d& truth, unsigned seed,
                                              bool shift_columns = false) {
  SlidingWindow window(config);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> phase(0.0, 1.0);
  double sq = 0;
  int n = 0;
  for (BackendInput in : scene.generate(frames)) {
    scanTheCar(scene, in, rng, shift_columns ? phase(rng) : -1.0);
    const BackendOutput out = window.process(in);
    if (in.frame < first_frame) continue;
    for (const TrackEstimate& e : out.tracks) {
      sq += (e.velocity.head<2>() - truth).squaredNorm();
      ++n;
    }
  }
  return {std::sqrt(sq / std::max(n, 1)), n};
}

// A backend whose registrations are held off by a point count no car reaches: what else a car's
// points measure (the line of sight, the side's ends), its boxes' noise growing with range as
// config/dlslot.yaml's.
inline BackendConfig registrationHeldOff() {
  BackendConfig c;
  c.compute_covariance = false;
  c.observation_sigma_growth_per_m = 0.035;
  c.registration_types = {"Car"};
  c.registration.min_points = 100000;
  return c;
}

}  // namespace dlslot::backend::test
