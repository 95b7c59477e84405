#include "backend/backend_config.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace dlslot::backend {

Mode parseMode(const std::string& name) {
  if (name == "slot") return Mode::kSlot;
  if (name == "two-stage") return Mode::kTwoStage;
  if (name == "odometry-only") return Mode::kOdometryOnly;
  throw std::invalid_argument("backend mode: expected slot, two-stage or odometry-only, got '" + name + "'");
}

std::string toString(Mode mode) {
  switch (mode) {
    case Mode::kSlot: return "slot";
    case Mode::kTwoStage: return "two-stage";
    case Mode::kOdometryOnly: return "odometry-only";
  }
  return "?";
}

namespace {

// N standard deviations > 0 under `key`; `components` names them for the error message.
template <int N>
Eigen::Matrix<double, N, 1> readSigmas(ConfigSection& s, const std::string& key, const std::string& components) {
  std::vector<double> v;
  s.get(key, v);
  if (static_cast<int>(v.size()) != N) {
    throw ConfigError(s.file() + ": " + s.path() + "." + key + ": expected " + std::to_string(N) +
                      " standard deviations [" + components + "], got " + std::to_string(v.size()) + " values");
  }
  Eigen::Matrix<double, N, 1> out;
  for (int i = 0; i < N; ++i) {
    if (!(v[i] > 0.0))
      throw ConfigError(s.file() + ": " + s.path() + "." + key + ": standard deviations must be > 0");
    out[i] = v[i];
  }
  return out;
}

Vector6 readSigmas(ConfigSection& s, const std::string& key) { return readSigmas<6>(s, key, "tx ty tz rx ry rz"); }

void require(bool ok, const ConfigSection& s, const std::string& key, const std::string& expected) {
  if (!ok) throw ConfigError(s.file() + ": " + s.path() + "." + key + ": expected " + expected);
}

}  // namespace

Vector6 BackendConfig::boxSigma(const std::string& type, bool moving) const {
  Vector6 sigma = moving ? observation_sigma : landmark_sigma;
  if (const auto it = heading_sigma_by_type.find(type); it != heading_sigma_by_type.end())
    sigma[5] = std::max(sigma[5], it->second);
  return sigma;
}

BackendConfig BackendConfig::read(ConfigSection& s) {
  BackendConfig c;
  const std::string mode = s.get<std::string>("mode");
  try {
    c.mode = parseMode(mode);
  } catch (const std::invalid_argument& e) {
    throw ConfigError(s.file() + ": " + s.path() + ".mode: " + e.what());
  }
  s.get("window_size", c.window_size);
  require(c.window_size >= 2, s, "window_size", "an integer >= 2");
  c.odometry_sigma = readSigmas(s, "odometry_sigma");
  c.observation_sigma = readSigmas(s, "observation_sigma");
  c.landmark_sigma = readSigmas(s, "landmark_sigma");
  c.pose_change_sigma = readSigmas(s, "pose_change_sigma");
  c.constant_velocity_sigma = readSigmas(s, "constant_velocity_sigma");
  c.first_pose_sigma = readSigmas(s, "first_pose_sigma");
  c.constant_acceleration_sigma = readSigmas<3>(s, "constant_acceleration_sigma", "x m, y m, z m");
  s.get("marginalize_acceleration", c.marginalize_acceleration);
  s.get("observation_sigma_growth_per_m", c.observation_sigma_growth_per_m);
  c.vehicle_motion_sigma = readSigmas<4>(s, "vehicle_motion_sigma", "lateral m, vertical m, roll rad, pitch rad");
  s.get("vehicle_types", c.vehicle_types);
  s.get("vehicle_acceleration", c.vehicle_acceleration);
  require(c.vehicle_acceleration >= 0.0, s, "vehicle_acceleration", "an acceleration >= 0 (m/s^2)");
  s.get("vehicle_lateral_jerk", c.vehicle_lateral_jerk);
  require(c.vehicle_lateral_jerk >= 0.0, s, "vehicle_lateral_jerk", "a jerk >= 0 (m/s^3)");
  ConfigSection headings = s.section("heading_sigma_by_type");
  for (const std::string& type : headings.keys()) {
    const double sigma = headings.get<double>(type);
    require(sigma > 0.0, headings, type, "a heading sigma > 0 (rad)");
    c.heading_sigma_by_type[type] = sigma;
  }
  headings.finish();
  require(c.observation_sigma_growth_per_m >= 0.0, s, "observation_sigma_growth_per_m", "a number >= 0 (1/m)");
  s.get("degraded_odometry_scale", c.degraded_odometry_scale);
  require(c.degraded_odometry_scale >= 1.0, s, "degraded_odometry_scale", "a number >= 1");
  s.get("use_odometry_covariance", c.use_odometry_covariance);
  std::vector<double> scale{c.odometry_covariance_scale.x(), c.odometry_covariance_scale.y()};
  s.get("odometry_covariance_scale", scale);
  require(scale.size() == 2 && scale[0] > 0.0 && scale[1] > 0.0, s, "odometry_covariance_scale",
          "two factors > 0 [translation, rotation]");
  c.odometry_covariance_scale = Eigen::Vector2d(scale[0], scale[1]);
  s.get("odometry_check", c.odometry_check.enabled);
  s.get("odometry_check_probability", c.odometry_check.probability);
  require(c.odometry_check.probability > 0.0 && c.odometry_check.probability < 1.0, s, "odometry_check_probability",
          "a probability between 0 and 1 (exclusive)");
  s.get("odometry_check_min_support", c.odometry_check.min_support);
  require(c.odometry_check.min_support >= 1, s, "odometry_check_min_support", "an object count >= 1");
  s.get("odometry_check_downweight", c.odometry_check.downweight);
  s.get("observation_loss", c.observation_loss);
  require(c.observation_loss == "none" || c.observation_loss == "huber" || c.observation_loss == "cauchy", s,
          "observation_loss", "none, huber or cauchy");
  s.get("observation_loss_scale", c.observation_loss_scale);
  require(c.observation_loss_scale > 0.0, s, "observation_loss_scale", "a number > 0");
  s.get("static_max_speed", c.static_max_speed);
  s.get("velocity_frames", c.velocity_frames);
  require(c.velocity_frames >= 1, s, "velocity_frames", "a frame count >= 1");
  s.get("walker_line_span_s", c.walker_line_span_s);
  require(c.walker_line_span_s >= 0.0, s, "walker_line_span_s", "a span >= 0 (s)");
  s.get("walker_rms_speed", c.walker_rms_speed);
  require(c.walker_rms_speed >= 0.0, s, "walker_rms_speed", "a speed >= 0 (m/s)");
  s.get("switch_min_sigmas", c.switch_min_sigmas);
  require(c.switch_min_sigmas >= 0.0, s, "switch_min_sigmas", "a number of sigmas >= 0");
  require(c.static_max_speed >= 0.0, s, "static_max_speed", "a speed >= 0 (m/s)");
  s.get("dynamic_min_sigmas", c.dynamic_min_sigmas);
  require(c.dynamic_min_sigmas >= 0.0, s, "dynamic_min_sigmas", "a number >= 0");
  s.get("switch_distance", c.switch_distance);
  require(c.switch_distance > 0.0, s, "switch_distance", "a distance > 0 (m)");
  s.get("switch_frames", c.switch_frames);
  require(c.switch_frames >= 1, s, "switch_frames", "an integer >= 1");
  s.get("max_iterations", c.max_iterations);
  require(c.max_iterations >= 1, s, "max_iterations", "an integer >= 1");
  s.get("function_tolerance", c.function_tolerance);
  s.get("gradient_tolerance", c.gradient_tolerance);
  s.get("parameter_tolerance", c.parameter_tolerance);
  s.get("compute_covariance", c.compute_covariance);
  s.get("registration_types", c.registration_types);
  s.get("registration_min_points", c.registration.min_points);
  require(c.registration.min_points >= 6, s, "registration_min_points", "an integer >= 6");
  s.get("registration_information_scale", c.registration.information_scale);
  require(c.registration.information_scale > 0.0, s, "registration_information_scale", "a number > 0");
  s.get("registration_accuracy_m", c.registration.accuracy_m);
  require(c.registration.accuracy_m >= 0.0, s, "registration_accuracy_m", "a distance >= 0 (m)");
  double accuracy_deg = c.registration.accuracy_rad * 180.0 / M_PI;
  s.get("registration_accuracy_deg", accuracy_deg);
  require(accuracy_deg >= 0.0, s, "registration_accuracy_deg", "an angle >= 0 (deg)");
  c.registration.accuracy_rad = accuracy_deg * M_PI / 180.0;
  s.get("registration_max_sigma", c.registration.max_sigma);
  require(c.registration.max_sigma > 0.0, s, "registration_max_sigma", "a distance > 0 (m)");
  s.get("registration_model_frames", c.registration.model_frames);
  require(c.registration.model_frames >= 1, s, "registration_model_frames", "an integer >= 1 (1: the previous scan alone)");
  s.get("registration_max_model_points", c.registration.max_model_points);
  require(c.registration.max_model_points >= c.registration.min_points, s, "registration_max_model_points",
          "an integer >= registration_min_points");
  s.get("registration_refine_boxes", c.registration_refine_boxes);
  s.get("registration_box_margin", c.registration_box_margin);
  require(c.registration_box_margin >= 0.0, s, "registration_box_margin", "a distance >= 0 (m)");
  s.get("registration_box_margin_sigmas", c.registration_box_margin_sigmas);
  require(c.registration_box_margin_sigmas >= 0.0, s, "registration_box_margin_sigmas", "a number >= 0 (standard deviations)");
  s.get("registration_missed_vehicles", c.registration_missed_vehicles);
  s.get("line_of_sight_min_points", c.line_of_sight_min_points);
  require(c.line_of_sight_min_points >= 1, s, "line_of_sight_min_points", "an integer >= 1");
  s.get("line_of_sight_young_min_points", c.line_of_sight_young_min_points);
  require(c.line_of_sight_young_min_points >= 1 && c.line_of_sight_young_min_points <= c.line_of_sight_min_points, s,
          "line_of_sight_young_min_points", "an integer in [1, line_of_sight_min_points]");
  s.get("line_of_sight_max_angle_deg", c.line_of_sight_max_angle_deg);
  require(c.line_of_sight_max_angle_deg >= 0.0 && c.line_of_sight_max_angle_deg <= 90.0, s, "line_of_sight_max_angle_deg",
          "an angle in [0, 90] (deg)");
  s.get("line_of_sight_pairs", c.line_of_sight_pairs);
  require(c.line_of_sight_pairs >= 0, s, "line_of_sight_pairs", "an integer >= 0 (0: not used)");
  s.get("line_of_sight_sigma", c.line_of_sight_sigma);
  require(c.line_of_sight_sigma > 0.0, s, "line_of_sight_sigma", "a speed > 0 (m/s)");
  s.get("line_of_sight_series", c.line_of_sight_series);
  // Its scans' times are the window's.
  require(c.line_of_sight_series >= 0 && c.line_of_sight_series <= c.window_size, s, "line_of_sight_series",
          "an integer in [0, window_size] (scans; 0: pairs judged by their points alone)");
  s.get("line_of_sight_tolerance", c.line_of_sight_tolerance);
  require(c.line_of_sight_tolerance > 0.0, s, "line_of_sight_tolerance", "a distance > 0 (m)");
  s.get("line_of_sight_chain", c.line_of_sight_chain);
  s.get("side_azimuth_step_deg", c.side_azimuth_step_deg);
  require(c.side_azimuth_step_deg >= 0.0 && c.side_azimuth_step_deg < 10.0, s, "side_azimuth_step_deg",
          "an angle in [0, 10) (deg; 0: not used)");
  s.get("side_length_tolerance", c.side_length_tolerance);
  require(c.side_length_tolerance > 0.0, s, "side_length_tolerance", "a distance > 0 (m)");
  s.get("face_heading", c.face_heading);
  s.get("registration_ground_clearance", c.registration_ground_clearance);
  require(c.registration_ground_clearance >= 0.0, s, "registration_ground_clearance", "a distance >= 0 (m)");
  s.get("solver_threads", c.solver_threads);
  require(c.solver_threads >= 1, s, "solver_threads", "an integer >= 1");
  return c;
}

Matrix6 sqrtInformation(const Vector6& sigma) { return sigma.cwiseInverse().asDiagonal(); }

}  // namespace dlslot::backend
