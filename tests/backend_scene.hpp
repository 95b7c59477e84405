// A synthetic scene for the backend tests and benchmark: an ego trajectory and objects given
// as functions of time, turned into per-frame BackendInputs with controlled noise (odometry
// chained from noisy deltas, boxes from noisy relative poses), as the odometry and tracker
// would publish them.
#pragma once

#include <cmath>
#include <functional>
#include <map>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "backend/backend_types.hpp"
#include "backend/se3.hpp"

namespace dlslot::backend::test {

struct SimObject {
  int id = 0;
  std::string type = "Car";
  Eigen::Vector3d size{4.5, 1.8, 1.5};
  std::function<Pose(double t)> pose;  // T_world_object
  std::function<bool(int frame)> visible = [](int) { return true; };
  bool dynamic_guess = false;  // what the tracker would guess
};

inline Pose planarPose(double x, double y, double yaw, double z = 0.0) {
  Pose T = Pose::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

// Moving on a circle arc (or a line when yaw_rate = 0) at constant speed, starting at pose0.
inline std::function<Pose(double)> constantTwist(const Pose& pose0, double speed, double yaw_rate) {
  return [=](double t) {
    Pose step = Pose::Identity();
    if (std::abs(yaw_rate) < 1e-12) {
      step.translation() = Eigen::Vector3d(speed * t, 0, 0);
    } else {
      const double a = yaw_rate * t, r = speed / yaw_rate;
      step.linear() = Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix();
      step.translation() = Eigen::Vector3d(r * std::sin(a), r * (1 - std::cos(a)), 0);
    }
    return pose0 * step;
  };
}

struct SimScene {
  std::function<Pose(double t)> ego = [](double) { return Pose::Identity(); };
  std::vector<SimObject> objects;
  double dt = 0.1;
  int64_t utime0 = 1'000'000;
  // Noise standard deviations per component [tx ty tz rx ry rz] (a zero switches it off).
  Vector6 odometry_noise = Vector6::Zero();
  // Box noise: centre (x y z, lidar frame) and yaw.
  Eigen::Vector3d box_noise = Eigen::Vector3d::Zero();
  double yaw_noise = 0.0;
  int init_after = 3;  // the tracker's g: observations before a trajectory is initialized
  std::set<int> frames_without_odometry;
  std::set<int> frames_without_associations;
  // Extra detections: frame -> (track id, box in the lidar frame), e.g. spurious ones.
  std::multimap<int, ObservationInput> extra;
  unsigned seed = 1;

  double time(int frame) const { return frame * dt; }
  Pose egoTruth(int frame) const { return ego(time(frame)); }
  Pose objectTruth(int id, int frame) const {
    for (const SimObject& o : objects)
      if (o.id == id) return o.pose(time(frame));
    return Pose::Identity();
  }

  std::vector<BackendInput> generate(int frames) const {
    std::mt19937 rng(seed);
    std::normal_distribution<double> n01(0.0, 1.0);
    auto noise6 = [&](const Vector6& sigma) {
      Vector6 v;
      for (int i = 0; i < 6; ++i) v[i] = sigma[i] * n01(rng);
      return v;
    };
    std::vector<BackendInput> out;
    std::map<int, int> seen;
    Pose odometry_pose = egoTruth(0);
    for (int f = 0; f < frames; ++f) {
      BackendInput in;
      in.frame = f;
      in.utime = utime0 + static_cast<int64_t>(std::llround(time(f) * 1e6));
      const Pose X = egoTruth(f);
      if (f > 0) {
        const Pose delta_true = egoTruth(f - 1).inverse() * X;
        const Pose delta = plus(delta_true, noise6(odometry_noise));
        odometry_pose = odometry_pose * delta;
        if (!frames_without_odometry.count(f)) {
          OdometryInput o;
          o.pose = odometry_pose;
          o.delta = delta;
          // The true noise (not definite when a component has none: then the backend uses
          // its configured sigmas).
          o.covariance = odometry_noise.cwiseAbs2().asDiagonal();
          in.odometry = o;
        }
      } else {
        OdometryInput o;
        o.pose = odometry_pose;
        in.odometry = o;
      }
      in.associations_missing = frames_without_associations.count(f) > 0;
      if (!in.associations_missing) {
        for (const SimObject& obj : objects) {
          if (!obj.visible(f)) continue;
          const Pose b = X.inverse() * obj.pose(time(f));
          ObservationInput obs;
          obs.track_id = obj.id;
          obs.box.type = obj.type;
          obs.box.id = obj.id;
          obs.box.size = obj.size;
          for (int i = 0; i < 3; ++i) obs.box.center[i] = b.translation()[i] + box_noise[i] * n01(rng);
          obs.box.yaw = yawOf(b.linear()) + yaw_noise * n01(rng);
          obs.initialized = ++seen[obj.id] >= init_after;
          obs.dynamic_guess = obj.dynamic_guess;
          in.observations.push_back(obs);
        }
        auto [lo, hi] = extra.equal_range(f);
        for (auto it = lo; it != hi; ++it) in.observations.push_back(it->second);
      }
      out.push_back(in);
    }
    return out;
  }
};

// The small scene of the node and process tests: driving at 10 m/s past one parked car with one
// car moving ahead, odometry and associations missing at the given frames.
inline SimScene parkedAndMovingScene(int frame_without_odometry, int frame_without_associations) {
  SimScene s;
  s.ego = constantTwist(Pose::Identity(), 10.0, 0.05);
  s.odometry_noise << 0.02, 0.02, 0.01, 0.002, 0.002, 0.003;
  s.box_noise << 0.1, 0.1, 0.05;
  SimObject parked, moving;
  parked.id = 1;
  parked.pose = [](double) { return planarPose(20, 6, 0.2); };
  moving.id = 2;
  moving.pose = constantTwist(planarPose(10, -3.5, 0), 12.0, 0.05);
  s.objects = {parked, moving};
  s.frames_without_odometry = {frame_without_odometry};
  s.frames_without_associations = {frame_without_associations};
  return s;
}

}  // namespace dlslot::backend::test
