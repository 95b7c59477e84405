// The detector's settings: the `detector` section of config/dlslot.yaml (every key required).
// The defaults here are the shipped values, so tests can start from DetectorConfig{}.
#pragma once

#include <string>

#include "detector/score_calibration.hpp"
#include "dlslot/config.hpp"

namespace dlslot::detector {

// Which points are looked at, and where the ground starts.
struct ScanWindow {
  double min_range_m = 2.5;       // returns from the ego vehicle itself lie inside
  double max_range_m = 60.0;      // horizontal range
  double sensor_height_m = 1.73;  // lidar above the road: the ground line starts here, under the sensor
};

// Per-sector ground line (ground_segmentation.hpp).
struct GroundConfig {
  int sectors = 360;                // azimuth sectors, each fitted on its own
  double bin_m = 1.0;               // range bins along a sector
  double max_step_m = 0.2;          // a kerb: ground may step up or down this much between bins...
  double max_slope = 0.15;          // ...plus this rise over run
  double height_threshold_m = 0.25;  // points this far above their cell's ground are obstacles
  double max_height_m = 4.0;        // ... up to this (above: overhangs, canopies, bridges)
};

// Range-image neighbourhood clustering (range_image_clustering.hpp).
struct ClusteringConfig {
  int columns = 2048;               // azimuth columns of the range image
  double row_step = 0.004;          // vertical pixel size in tan(elevation) (HDL-64E beams are 0.0058-0.009 apart)
  int neighbour_rows = 3;           // a point's neighbours: this many rows up and down...
  int neighbour_columns = 2;        // ...and columns left and right
  double distance_m = 0.45;         // neighbours closer than max(distance_m, distance_per_m x range) join
  double distance_per_m = 0.02;
  int min_points = 8;               // smaller clusters are noise
  // Clusters whose bird's-eye boxes overlap (grown by join_margin_m) are one object when the joined
  // box's diagonal stays within join_max_diagonal_m (joinOverlappingClusters()).
  double join_margin_m = 0.4;
  double join_max_diagonal_m = 7.0;
};

// One class's size window (visible extent after the vehicle prior completed it).
struct SizeWindow {
  double min_length_m = 0, max_length_m = 0, min_width_m = 0, max_width_m = 0, min_height_m = 0, max_height_m = 0;
  // height_is_lower_bound: the object was cut off by the top beam, so it may be taller than h.
  bool contains(double l, double w, double h, bool height_is_lower_bound = false) const {
    return l >= min_length_m && l <= max_length_m && w >= min_width_m && w <= max_width_m &&
           (h >= min_height_m || height_is_lower_bound) && h <= max_height_m;
  }
};

// Classes from size and shape (object_class.hpp).
struct ClassConfig {
  // The size a car is completed to when only part of it is seen (length, width).
  double car_prior_length_m = 4.2, car_prior_width_m = 1.75;
  // A visible face longer than this is a car's side, shorter its back or front.
  double car_side_min_m = 2.3;
  // A short, wide cluster (neither a side nor a back) is a car's corner only with this share of its
  // points on the rectangle's edges (foliage has fewer).
  double min_corner_edge_fraction = 0.4;
  // ... and a wide one as long as a side this share (foliage has almost none on its edges).
  double min_side_edge_fraction = 0.2;
  // The shortest seen face completed to a car (a car's back is 1.5-1.9 m wide).
  double min_vehicle_face_m = 1.4;
  // A seen side at least car_side_min_m long whose quarters' tops differ by less than this is a
  // wall or a barrier (ClusterShape::profile_step).
  double min_profile_step_m = 0.2;
  double level_max_width_m = 1.5;  // ... when seen no wider than this (a wider L-shape is a corner)
  // A cluster whose quarters' tops differ by more than this is foliage, not a vehicle.
  double max_vehicle_profile_step_m = 1.3;
  // A cyclist seen from the side has a rider above low wheels: its quarters' tops differ by at least
  // this. A van's or a truck's back, as wide as a bicycle is long, is level (highway seeds 1-5: 11 of
  // the Car group's misses were vans' backs taken for cyclists).
  double cyclist_min_profile_step_m = 0.4;
  // The lowest height of a (partly seen) vehicle drops by this per metre of range: far away the top
  // beams are ~0.2 m apart at the roof and the ground under the vehicle is hidden by it, so the
  // ground line climbs its lower body (highway seeds 1-5: cars at 25-40 m seen 0.6-1.0 m tall).
  double vehicle_min_height_drop_per_m = 0.008;
  // A truck's back: a face at least this wide (wider than cars and vans), completed to this length.
  double truck_min_face_m = 2.3;
  double truck_prior_length_m = 8.0;
  // People and cyclists show their near half: their boxes grow away from the sensor to at least
  // these footprints (length, width), as labels and learned detectors give them (a seen 0.47 x 0.32 m
  // pedestrian against a 0.81 x 0.62 m label overlaps it by under the 0.25 3-D IoU the KITTI protocol asks).
  double pedestrian_prior_length_m = 0.8, pedestrian_prior_width_m = 0.6;
  double cyclist_prior_length_m = 1.7, cyclist_prior_width_m = 0.6;
  SizeWindow car{3.2, 5.4, 1.4, 2.2, 1.0, 1.9};
  SizeWindow van{4.2, 6.5, 1.7, 2.4, 1.9, 2.8};
  SizeWindow truck{6.0, 14.0, 2.0, 3.0, 2.5, 4.2};
  SizeWindow pedestrian{0.2, 1.1, 0.15, 0.9, 1.2, 2.05};
  SizeWindow cyclist{1.2, 2.2, 0.25, 1.0, 1.1, 2.05};
  double pole_max_width_m = 0.3;     // thinner and cut off by the top beam, or taller than a person: a pole
  double max_bottom_m = 1.2;         // a cluster starting higher above the ground is an overhang (a car seen
                                     // over a median barrier starts ~1 m up)
  // Unknown: object-like (footprint within this, height within this) but no class fits: its points
  // are still removed for the odometry; anything larger or flatter is background (not published).
  double unknown_max_length_m = 2.0, unknown_max_height_m = 2.2, unknown_min_height_m = 1.2;
  double top_tan = 0.035;            // tan of the top beam's elevation (HDL-64E: +2 deg; config: top_beam_deg)
};

struct DetectorConfig {
  ScanWindow window;
  GroundConfig ground;
  ClusteringConfig clustering;
  ClassConfig classes;
  ScoreCalibration scores;

  // Throws ConfigError naming the file and the key.
  static DetectorConfig read(ConfigSection section);
  // Throws std::invalid_argument naming the first setting out of range.
  void validate() const;
};

}  // namespace dlslot::detector
