#include "detector/detector_config.hpp"

#include <cmath>
#include <stdexcept>
#include <vector>

namespace dlslot::detector {

namespace {

// [min, max] of one size window key.
void readRange(ConfigSection& s, const std::string& key, double& lo, double& hi) {
  std::vector<double> v;
  s.get(key, v);
  if (v.size() != 2 || !(v[0] >= 0) || !(v[1] >= v[0]))
    throw ConfigError(s.file() + ": " + s.path() + "." + key + ": expected [min, max] with 0 <= min <= max");
  lo = v[0];
  hi = v[1];
}

// [length, width] of a prior box size, both > 0.
void readSize(ConfigSection& s, const std::string& key, double& length, double& width) {
  std::vector<double> v;
  s.get(key, v);
  if (v.size() != 2 || !(v[0] > 0) || !(v[1] > 0))
    throw ConfigError(s.file() + ": " + s.path() + "." + key + ": expected [length, width], both > 0");
  length = v[0];
  width = v[1];
}

SizeWindow readWindow(ConfigSection s) {
  SizeWindow w;
  readRange(s, "length_m", w.min_length_m, w.max_length_m);
  readRange(s, "width_m", w.min_width_m, w.max_width_m);
  readRange(s, "height_m", w.min_height_m, w.max_height_m);
  s.finish();
  return w;
}

}  // namespace

DetectorConfig DetectorConfig::read(ConfigSection s) {
  DetectorConfig c;
  s.get("min_range_m", c.window.min_range_m);
  s.get("max_range_m", c.window.max_range_m);
  s.get("sensor_height_m", c.window.sensor_height_m);
  {
    ConfigSection g = s.section("ground");
    g.get("sectors", c.ground.sectors);
    g.get("bin_m", c.ground.bin_m);
    g.get("max_step_m", c.ground.max_step_m);
    g.get("max_slope", c.ground.max_slope);
    g.get("height_threshold_m", c.ground.height_threshold_m);
    g.get("max_height_m", c.ground.max_height_m);
    g.finish();
  }
  {
    ConfigSection k = s.section("clustering");
    k.get("columns", c.clustering.columns);
    k.get("row_step", c.clustering.row_step);
    k.get("neighbour_rows", c.clustering.neighbour_rows);
    k.get("neighbour_columns", c.clustering.neighbour_columns);
    k.get("distance_m", c.clustering.distance_m);
    k.get("distance_per_m", c.clustering.distance_per_m);
    k.get("min_points", c.clustering.min_points);
    k.get("join_margin_m", c.clustering.join_margin_m);
    k.get("join_max_diagonal_m", c.clustering.join_max_diagonal_m);
    k.finish();
  }
  {
    ConfigSection k = s.section("classes");
    ClassConfig& cl = c.classes;
    readSize(k, "car_prior_size_m", cl.car_prior_length_m, cl.car_prior_width_m);
    k.get("car_side_min_m", cl.car_side_min_m);
    k.get("min_corner_edge_fraction", cl.min_corner_edge_fraction);
    k.get("min_side_edge_fraction", cl.min_side_edge_fraction);
    k.get("min_vehicle_face_m", cl.min_vehicle_face_m);
    k.get("min_profile_step_m", cl.min_profile_step_m);
    k.get("level_max_width_m", cl.level_max_width_m);
    k.get("max_vehicle_profile_step_m", cl.max_vehicle_profile_step_m);
    k.get("cyclist_min_profile_step_m", cl.cyclist_min_profile_step_m);
    k.get("vehicle_min_height_drop_per_m", cl.vehicle_min_height_drop_per_m);
    k.get("truck_min_face_m", cl.truck_min_face_m);
    k.get("truck_prior_length_m", cl.truck_prior_length_m);
    readSize(k, "pedestrian_prior_size_m", cl.pedestrian_prior_length_m, cl.pedestrian_prior_width_m);
    readSize(k, "cyclist_prior_size_m", cl.cyclist_prior_length_m, cl.cyclist_prior_width_m);
    cl.car = readWindow(k.section("car"));
    cl.van = readWindow(k.section("van"));
    cl.truck = readWindow(k.section("truck"));
    cl.pedestrian = readWindow(k.section("pedestrian"));
    cl.cyclist = readWindow(k.section("cyclist"));
    k.get("pole_max_width_m", cl.pole_max_width_m);
    k.get("max_bottom_m", cl.max_bottom_m);
    k.get("unknown_max_length_m", cl.unknown_max_length_m);
    readRange(k, "unknown_height_m", cl.unknown_min_height_m, cl.unknown_max_height_m);
    k.get("top_beam_deg", cl.top_tan);
    cl.top_tan = std::tan(cl.top_tan * M_PI / 180.0);
    k.finish();
  }
  c.scores = ScoreCalibration::read(s.section("score_calibration"));
  s.finish();
  try {
    c.validate();
  } catch (const std::invalid_argument& e) {
    throw ConfigError(s.file() + ": " + s.path() + "." + e.what());
  }
  return c;
}

void DetectorConfig::validate() const {
  auto need = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument(what);
  };
  need(window.min_range_m >= 0 && window.max_range_m > window.min_range_m,
       "max_range_m: expected > min_range_m >= 0");
  need(window.max_range_m <= 200, "max_range_m: expected <= 200");
  need(window.sensor_height_m > 0 && window.sensor_height_m < 10, "sensor_height_m: expected in (0, 10)");
  need(ground.sectors >= 8 && ground.sectors <= 4096, "ground.sectors: expected 8..4096");
  need(ground.bin_m >= 0.1, "ground.bin_m: expected >= 0.1");
  need(ground.max_step_m >= 0 && ground.max_slope >= 0, "ground.max_step_m, max_slope: expected >= 0");
  need(ground.height_threshold_m > 0 && ground.max_height_m > ground.height_threshold_m,
       "ground.max_height_m: expected > height_threshold_m > 0");
  need(clustering.columns >= 64 && clustering.columns <= 16384, "clustering.columns: expected 64..16384");
  need(clustering.row_step >= 0.0005 && clustering.row_step <= 0.1, "clustering.row_step: expected 0.0005..0.1");
  need(clustering.neighbour_rows >= 1 && clustering.neighbour_rows <= 8, "clustering.neighbour_rows: expected 1..8");
  need(clustering.neighbour_columns >= 1 && clustering.neighbour_columns <= 8,
       "clustering.neighbour_columns: expected 1..8");
  need(clustering.distance_m > 0 && clustering.distance_per_m >= 0, "clustering.distance_m: expected > 0");
  need(clustering.min_points >= 1, "clustering.min_points: expected >= 1");
  need(classes.cyclist_min_profile_step_m >= 0, "classes.cyclist_min_profile_step_m: expected >= 0");
  need(classes.vehicle_min_height_drop_per_m >= 0 && classes.vehicle_min_height_drop_per_m < 0.05,
       "classes.vehicle_min_height_drop_per_m: expected in [0, 0.05)");
  need(classes.truck_min_face_m > 0 && classes.truck_prior_length_m > 0,
       "classes.truck_min_face_m, truck_prior_length_m: expected > 0");
  need(classes.car_prior_length_m > 0 && classes.car_prior_width_m > 0, "classes.car_prior_size_m: expected > 0");
}

}  // namespace dlslot::detector
