#include "sensor_model.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "rng.hpp"

namespace dlslot::sim {

constexpr double kDeg = M_PI / 180.0;

SensorSpec idealSensor(SensorSpec s) {
  s.range_noise_per_100m = 0;
  s.footprint_noise = 0;
  s.dropout_signal = 0;
  s.azimuth_phase = false;
  s.beam_elevation_error_deg = s.beam_azimuth_error_deg = s.beam_range_bias_m = 0;
  s.vertical_angle_error_deg = 0;
  s.motion_distortion = false;
  s.deskewed = false;
  s.vegetation_mean_free_path_m = 0;
  s.fences = 0;
  return s;
}

std::vector<BeamError> beamErrors(const SensorSpec& sensor, uint64_t key) {
  std::vector<BeamError> e(sensor.beams);
  for (int b = 0; b < sensor.beams; ++b) {
    Rng rng(streamKey({key, static_cast<uint64_t>(b)}));
    // Drawn whether used or not, so switching one residual off leaves the others as they were.
    const double el = rng.normal(), az = rng.normal(), range = rng.normal();
    e[b].elevation_rad = (sensor.beam_elevation_error_deg * el + sensor.vertical_angle_error_deg) * kDeg;
    e[b].azimuth_rad = sensor.beam_azimuth_error_deg * az * kDeg;
    e[b].range_bias_m = sensor.beam_range_bias_m * range;
  }
  return e;
}

double azimuthPhase(const SensorSpec& sensor, uint64_t frame_key) {
  if (!sensor.azimuth_phase) return 0.0;
  Rng rng(streamKey({frame_key, 0xa21u}));
  return rng.uniform();
}

double columnAzimuth(const SensorSpec& sensor, int column, double phase) {
  return 2 * M_PI * (column + phase) / sensor.azimuth_steps;
}

double firingTime(const SensorSpec& sensor, double azimuth, double period_s) {
  if (!sensor.motion_distortion) return 0.0;
  const double a = std::remainder(azimuth, 2 * M_PI);  // (-pi, pi]
  return -a / (2 * M_PI) * period_s;
}

double rangeSigma(const SensorSpec& sensor, double r, double cos_incidence) {
  const double c = std::clamp(std::abs(cos_incidence), 0.0, 1.0);
  const double tan_inc = std::min(10.0, std::sqrt(std::max(0.0, 1.0 - c * c)) / std::max(c, 1e-9));
  const double base = sensor.range_noise_m + sensor.range_noise_per_100m * r / 100.0;
  const double footprint = sensor.footprint_noise * r * sensor.beam_divergence_mrad * 1e-3 * tan_inc;
  return std::hypot(base, footprint);
}

double dropoutProbability(const SensorSpec& sensor, double r, double cos_incidence, double reflectivity) {
  double weak = 0.0;
  if (sensor.dropout_signal > 0) {
    const double signal = reflectivity * std::abs(cos_incidence) * (100.0 / r) * (100.0 / r);
    weak = 1.0 / (1.0 + std::pow(signal / sensor.dropout_signal, sensor.dropout_steepness));
  }
  return sensor.dropout + (1.0 - sensor.dropout) * weak;
}

Pose SweepMotion::at(double t) const {
  Pose T = Pose::Identity();
  const double rate = omega.norm();
  const Eigen::Matrix3d dR = rate > 1e-15 ? Eigen::AngleAxisd(rate * t, omega / rate).toRotationMatrix()
                                          : Eigen::Matrix3d::Identity();
  T.linear() = dR * T_ref.linear();
  T.translation() = T_ref.translation() + velocity * t;
  return T;
}

SweepMotion sweepMotion(const Pose* prev, const Pose& cur, const Pose* next, double period_s) {
  SweepMotion m;
  m.T_ref = cur;
  const Pose& a = prev ? *prev : cur;
  const Pose& b = next ? *next : cur;
  const int steps = (prev ? 1 : 0) + (next ? 1 : 0);
  if (steps == 0) return m;
  const double dt = steps * period_s;
  m.velocity = (b.translation() - a.translation()) / dt;
  const Eigen::AngleAxisd aa(Eigen::Matrix3d(b.linear() * a.linear().transpose()));
  m.omega = aa.axis() * aa.angle() / dt;
  return m;
}

}  // namespace dlslot::sim
