// A scenario: everything the simulator needs to build a world and drive through it, read from a
// YAML file in config/scenarios/ (so users can write their own). Distances in metres, angles in
// degrees in the file (radians in the structs), times in seconds, speeds in m/s.
#pragma once

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace dlslot::sim {

// A value drawn uniformly from [lo, hi] (a single number in the file means lo == hi).
struct Interval {
  double lo = 0.0, hi = 0.0;
};

// A drivable curve: a start pose and straight or circular pieces; curvature changes are smoothed
// over `transition_m` so headings and yaw rates are continuous (no jumps in the ego's motion).
struct RouteSpec {
  Eigen::Vector2d start = Eigen::Vector2d::Zero();
  double start_heading = 0.0;  // rad
  struct Piece {
    double length_m = 0.0;
    double curvature = 0.0;  // 1/m, positive = left turn
  };
  std::vector<Piece> pieces;
  double transition_m = 10.0;
};

struct ParkingSpec {      // parked vehicles along a road (both sides)
  double offset_m = 0.0;  // distance of the parked cars' centres from the centreline
  Interval spacing_m;     // centre to centre
  double fill = 1.0;      // fraction of slots occupied
  double angle = 0.0;     // rad; 0 = parallel parking, pi/2 = perpendicular stalls
};

struct RoadsideSpec {        // static structure along both sides of a road
  double frontage_m = 12.0;  // building fronts start this far from the centreline
  double buildings = 0.0;    // fraction of the frontage with buildings
  Interval building_length_m{8, 30}, building_depth_m{8, 20}, building_height_m{5, 20};
  double walls = 0.0;                                // probability of a wall closing a gap between buildings
  double poles_every_m = 0.0, poles_offset_m = 7.0;  // 0 = none
  double trees_every_m = 0.0, trees_offset_m = 9.0;
  double bushes_every_m = 0.0;       // scattered vegetation beyond the frontage
  double guard_rail_offset_m = 0.0;  // 0 = none
  bool median_barrier = false;
  double noise_walls = 0.0;  // fraction of the frontage with a 3-4 m noise barrier
};

struct RoadSpec {
  std::string name;
  RouteSpec route;
  std::vector<double> lanes;   // lane centres, m left of the centreline; lanes left of it drive the other way
  double carriageway_m = 7.0;  // driving width: parked cars and structure stay out of it
  double clear_m = 20.0;       // width kept free of static structure (carriageway + parking + sidewalks)
  std::optional<ParkingSpec> parking;
  RoadsideSpec roadside;
};

// A traffic light: paths entering the disk at `at` with a heading within 45 deg of `axis`
// (either direction) stop at its edge while red.
struct SignalSpec {
  Eigen::Vector2d at = Eigen::Vector2d::Zero();
  double radius_m = 10.0;
  double axis = 0.0;          // rad
  std::vector<Interval> red;  // time intervals, s
};

// Where an agent (or the ego) moves: a lane of a road, its own route, or across a road.
struct PathSpec {
  std::string road;  // with `lane`
  double lane = 0.0;
  std::optional<RouteSpec> route;
  std::optional<double> crossing_s_m;  // straight across `road` at this arc length (pedestrians)
};

struct EgoSpec {
  PathSpec path;
  double start_s_m = 0.0;
  std::vector<std::pair<double, double>> speed_profile;  // (time s, speed m/s) knots
  // The body's ride on its suspension: rms pitch and roll (rad) and rms heave (m), each a
  // sum of three sinusoids of 0.7-2.5 Hz with seeded phases. The lidar turns with the body, during
  // the sweep too. 0 = a rigid ride. With ride_full_speed_mps > 0 the road excites it: full from
  // that speed, in proportion below, none at rest (BodyRide::at); 0 = the same at every speed.
  // The defaults rock 5x harder than a KITTI car (0.8 deg a frame against 0.08-0.21, and at rest);
  // body_pitch_roll 0.1 deg with ride_full_speed_mps 2 matches KITTI's GPS/INS poses (docs/ego.md,
  // "The simulator's body ride against KITTI's poses").
  double body_pitch_roll = 0.5 * M_PI / 180.0;
  double body_heave_m = 0.005;
  double ride_full_speed_mps = 0.0;
};

struct TrafficSpec {
  PathSpec path;
  std::map<std::string, double> classes;  // class name -> relative weight
  int count = 0;
  Interval start_s_m, speed_mps;
  Interval start_time_s;          // agents stand still until then
  double speed_changes = 0.0;     // mean number of cruise-speed changes per agent
  double stop_probability = 0.0;  // chance an agent stops for a while somewhere
};

struct SensorSpec {  // HDL-64E-like by default; the imperfections of a real one, see sensor_model.hpp
  // Beam layout: 64 beams are the HDL-64E's own (non-uniform) elevations; any other count is spread
  // evenly from top_elevation_deg (beam 0) to bottom_elevation_deg, as on 16/32/128-beam sensors.
  int beams = 64;
  double top_elevation_deg = 2.0, bottom_elevation_deg = -24.33;
  int azimuth_steps = 2000;
  double max_range_m = 120.0, min_range_m = 2.5;
  double height_m = 1.73;
  // Range noise: sigma_0 + per-100-m growth, in quadrature with the footprint's depth spread.
  double range_noise_m = 0.02;
  double range_noise_per_100m = 0.02;
  double beam_divergence_mrad = 2.0;
  double footprint_noise = 0.25;  // sigma as a fraction of r * divergence * tan(incidence); 0 = off
  // Lost returns: random, and where the received signal is weak (0 = off).
  double dropout = 0.02;
  double dropout_signal = 0.02, dropout_steepness = 2.0;
  bool azimuth_phase = true;  // firing phase changes from revolution to revolution
  // Per-beam calibration residuals (sigmas, drawn once per seed) and KITTI's common vertical error.
  double beam_elevation_error_deg = 0.05, beam_azimuth_error_deg = 0.05, beam_range_bias_m = 0.02;
  // KITTI's scans: the rays point 0.22 deg higher than the stored points say (on by default: it is
  // what makes A-LOAM drift as on KITTI, see config/scenarios/README.md; 0 = off).
  double vertical_angle_error_deg = 0.22;
  bool motion_distortion = true;  // points fired across the sweep while everything moves
  bool deskewed = false;          // written in the reference-time frame (KITTI odometry), not as seen
  // Partly transparent clutter: rays go into tree crowns and bushes an exponential depth of this
  // mean (0 = solid), and this fraction of the gaps' walls are wire fences passing fence_pass of the rays.
  double vegetation_mean_free_path_m = 0.6;
  double fences = 0.5, fence_pass = 0.5;
};

struct GroundSpec {
  double max_slope = 0.03;  // bound on the grade of the gentle undulation
  Interval wavelength_m{150, 400};
};

struct LabelSpec {
  int min_points = 10;  // fewer points on an object: DontCare
};

struct DetectorSpec {            // simulated 3D detector (SECOND-like probabilities as scores)
  double points_for_half = 8.0;  // detection probability p_max (1 - 2^(-points / points_for_half))
  double max_probability = 0.97;
  // White noise of the centre, per axis: position_noise_m + position_noise_per_m x range along the
  // object's heading, position_noise_across_ratio x that across it (1: the same in every direction).
  double position_noise_m = 0.08, position_noise_per_m = 0.003, position_noise_across_ratio = 1.0;
  // A box's centre also drifts slowly off the object's (a partly seen car's box follows what is
  // seen of it): standard deviation drift_m + drift_per_m x range along the object's heading,
  // drift_across_ratio x that across it, correlated over drift_time_s along and
  // drift_across_time_s across (exp(-dt / time); the latter defaults to the former). Off by
  // default; config/scenarios/README.md has the values measured on KITTI's PointRCNN boxes.
  double drift_m = 0.0, drift_per_m = 0.0, drift_across_ratio = 0.2, drift_time_s = 3.0, drift_across_time_s = 3.0;
  double yaw_noise = 0.04;     // rad
  double heading_flip = 0.02;  // chance a vehicle's heading is off by pi
  double size_noise = 0.04;    // relative
  double false_positives_per_frame = 0.8;
  double ghost_fraction = 0.05;  // share of poles/trees/bushes that repeatedly look like pedestrians
};

struct Scenario {
  std::string name;
  std::string file;  // where it was read from
  int frames = 300;
  uint64_t seed = 1;
  double frame_period_s = 0.1;
  SensorSpec sensor;
  GroundSpec ground;
  std::vector<RoadSpec> roads;
  std::vector<SignalSpec> signals;
  EgoSpec ego;
  std::vector<TrafficSpec> traffic;
  LabelSpec labels;
  DetectorSpec detector;
  YAML::Node source;  // the file as read (written back with the seed and frames used)
};

// Reads and checks a scenario file; throws ConfigError naming the file, the key and what was expected.
Scenario loadScenario(const std::string& path);
// NAME -> <source dir>/config/scenarios/NAME.yaml; an existing file path is returned as it is.
std::string resolveScenario(const std::string& name_or_path, const std::string& source_dir);
// The scenario as used (its file with `seed` and `frames` set), for reproducing a sequence.
void writeScenario(const std::string& path, const Scenario& scenario);

}  // namespace dlslot::sim
