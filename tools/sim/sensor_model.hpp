// The imperfections of a real HDL-64E that make LiDAR odometry drift, as pure functions
// the ray caster (sensor.cpp) calls and the tests check against: firing that is not locked to the
// rotation, per-beam calibration residuals, range noise growing with range and incidence, returns
// lost when the received signal is weak, and the sweep's 0.1 s of motion.
#pragma once

#include <array>
#include <cstdint>

#include "dlslot/types.hpp"
#include "scenario.hpp"

namespace dlslot::sim {

// The same sensor without the imperfections (the ideal lidar: nominal
// angles, fixed firing, constant range noise, random dropout only, instantaneous, solid foliage).
SensorSpec idealSensor(SensorSpec sensor);

// What one laser's factory calibration gets wrong (true minus calibrated): its ray leaves at
// elevation + elevation_rad and azimuth + azimuth_rad, and it reports ranges range_bias_m too long.
struct BeamError {
  double elevation_rad = 0.0, azimuth_rad = 0.0, range_bias_m = 0.0;
};
// Per-beam residuals drawn N(0, sigma) from `key` (the sensor of one scenario seed), plus the
// common vertical-angle error (KITTI's scans: the rays point vertical_angle_error_deg higher than
// the stored points say). All zero when the sensor's calibration residuals are off.
std::array<BeamError, 64> beamErrors(const SensorSpec& sensor, uint64_t key);

// Phase of the first firing of a revolution, in columns [0, 1): a lidar's firing clock runs free of
// its rotation, so successive scans sample different azimuths. 0 when azimuth_phase is off.
double azimuthPhase(const SensorSpec& sensor, uint64_t frame_key);
// Azimuth (rad) of column `column` in a revolution with that phase.
double columnAzimuth(const SensorSpec& sensor, int column, double phase);

// Firing time (s) of a ray at azimuth `azimuth` (rad, lidar frame) relative to the scan's reference
// time, when the lidar faces straight ahead (KITTI triggers its cameras then; poses and labels are
// for that instant). The head spins clockwise seen from above like an HDL-64E, so a sweep runs
// from behind (-period/2) over the left, ahead (0) and the right back to behind (+period/2).
// 0 when motion distortion is off.
double firingTime(const SensorSpec& sensor, double azimuth, double period_s);

// Standard deviation (m) of a range measurement at range r (m) on a surface whose normal makes
// `cos_incidence` with the ray: sigma_0 + k_r r / 100 in quadrature with the depth the beam's
// footprint spans on the surface, footprint_noise * r * divergence * tan(incidence), tan capped at
// 10 (85 deg).
double rangeSigma(const SensorSpec& sensor, double r, double cos_incidence);

// Probability that a return is lost: the random dropout, and the weak-signal loss
// 1 / (1 + (signal / dropout_signal)^dropout_steepness) with signal = reflectivity * cos(incidence)
// * (100 m / r)^2 (the received power of a Lambertian target, relative to a white wall at 100 m).
double dropoutProbability(const SensorSpec& sensor, double r, double cos_incidence, double reflectivity);

// Rigid motion of a body over the sweep: its pose at the reference time and its constant twist
// (velocity, yaw-pitch-roll rate as a rotation vector per second), both in the map frame.
struct SweepMotion {
  Pose T_ref = Pose::Identity();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  // m/s, map frame
  Eigen::Vector3d omega = Eigen::Vector3d::Zero();     // rad/s, map frame
  Pose at(double t) const;                             // pose t seconds after the reference time
};
// The motion through pose `k` from its neighbours (central difference; one-sided at the ends).
SweepMotion sweepMotion(const Pose* prev, const Pose& cur, const Pose* next, double period_s);

}  // namespace dlslot::sim
