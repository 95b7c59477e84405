// Every parameter of the odometry, with A-LOAM's KITTI (HDL-64) values as defaults. The node
// reads them from the `odometry:` section of config/dlslot.yaml (odometry_config.cpp).
#pragma once

#include <string>
#include <vector>

#include "dlslot/config.hpp"

namespace dlslot::odometry {

// Feature extraction (A-LOAM scanRegistration; LOAM section V-A).
struct FeatureConfig {
  // "hdl64": A-LOAM's piecewise rule for the KITTI HDL-64E (uses beams 0..50 only);
  // "uniform": num_beams lasers evenly spaced from max_vertical_deg (beam 0) to min_vertical_deg.
  std::string beam_model = "hdl64";
  int num_beams = 64;
  double min_vertical_deg = -24.9;
  double max_vertical_deg = 2.0;
  double min_range_m = 5.0;            // closer points hit the vehicle or are too dense
  int curvature_half_window = 5;       // neighbours on each side used for curvature
  double max_azimuth_gap_deg = 1.0;    // a larger step between ring neighbours is a gap
  int sectors_per_beam = 6;            // features are picked evenly around each ring
  double edge_curvature_min = 0.1;     // curvature above: edge candidate
  double plane_curvature_max = 0.1;    // curvature below: plane candidate
  int sharp_per_sector = 2;
  int less_sharp_per_sector = 20;
  int flat_per_sector = 4;
  int suppression_half_window = 5;     // neighbours of a picked point that cannot be picked
  double suppression_max_gap_m = 0.2236;  // ...unless separated by a larger gap (sqrt(0.05))
  double less_flat_spacing_m = 0.2;    // along-ring spacing of the less-flat points kept
};

// One Ceres registration: correspondences are searched up to `outer_iterations` times, each
// followed by `solver_iterations` Levenberg-Marquardt steps with a Huber loss; a solve that moves
// the pose less than converged_step_* ends the loop (a new search would find the same pairs).
struct SolverConfig {
  int outer_iterations = 2;
  int solver_iterations = 4;
  double huber_delta_m = 0.1;
  double converged_step_m = 0.02;
  double converged_step_deg = 0.1;
};

// Scan-to-scan odometry (A-LOAM laserOdometry).
struct ScanToScanConfig {
  // true: A-LOAM's order, every scan registered to the previous scan, then to the map from there.
  // false: the map registration starts from the constant-velocity prediction, and scan-to-scan
  // runs only where that is not enough: the second scan (no velocity yet) and a map
  // registration that fails or jumps (max_correction_*; it is then redone from the scan-to-scan
  // result). As KISS-ICP registers to its map from a constant-velocity prediction alone. On the
  // real slice the same accuracy for a third less CPU, on the simulated drives better t_rel
  // (scan-to-scan locks onto passing traffic): docs/results.md, "Odometry speed".
  bool every_scan = false;
  SolverConfig solver;
  double max_match_distance_m = 5.0;  // nearest previous feature farther than this: no match
  int nearby_beams = 2;               // second/third match points come from beams this close
  int candidates = 10;                // ...among this many nearest previous points
  int min_correspondences = 30;
  // Forward motion hypotheses (m per scan) for the second scan of a sequence (no velocity yet)
  // and for a velocity check that found the prediction suspect (lidar_odometry.cpp):
  // registration starts from 0, spacing, 2 spacing, ...
  // max_forward_m ahead and keeps the solution with the most inliers. The spacing is what one
  // registration reaches: along a highway its nearest-neighbour correspondences stick to the
  // rails and the road, so it moves only 0.1-0.15 m towards a motion 2 m away, but from 0.3 m
  // off it lands within 0.1 m (docs/ego.md). The largest is 45 m/s at KITTI's 10 Hz, above any
  // drive here.
  double max_forward_m = 4.5;
  double hypothesis_spacing_m = 0.25;
};

// Scan-to-map refinement against a local map (A-LOAM laserMapping).
struct ScanToMapConfig {
  // A solve that moves the pose less than 5 cm / 0.25 deg ends the search: a second search after
  // such a step leaves the accuracy on the real slice and the simulated drives as it is (docs/results.md,
  // "Odometry speed"), and each search costs about as much as the rest of a frame.
  SolverConfig solver{2, 4, 0.1, 0.05, 0.25};
  double edge_voxel_m = 0.4;          // voxel size of the edge map and of the scan's edge queries
  double plane_voxel_m = 0.8;         // same for planes
  int neighbors = 5;                  // map points fitted to a line or plane per query
  double max_neighbor_distance_m = 1.0;
  double edge_eigen_ratio = 3.0;      // largest/second eigenvalue of a line's neighbours
  double edge_max_tilt_deg = 90.0;    // lines farther than this from vertical are not matched
  double plane_max_deviation_m = 0.2; // every neighbour must be this close to the fitted plane
  double map_radius_m = 100.0;        // map points farther (horizontally) from the vehicle are dropped
  int min_correspondences = 50;
};

struct OdometryConfig {
  FeatureConfig features;
  ScanToScanConfig scan_to_scan;
  ScanToMapConfig scan_to_map;
  // Paper III-D: A-LOAM* removes the points of detected objects before feature extraction.
  bool remove_detected_objects = true;
  double box_margin_m = 0.3;          // boxes are grown by this on every side but the bottom
  // Points lower than this above a box's floor are ground and kept (box_filter.hpp,
  // removalVolume); -box_margin_m removes the ground around the box as well.
  double ground_clearance_m = 0.25;
  int min_points = 1000;              // fewer points after filtering: constant-velocity fallback
  int min_edge_features = 10;
  int min_plane_features = 50;
  // A solved pose farther than this from the constant-velocity prediction is a failed solve.
  double max_correction_m = 2.0;
  double max_correction_deg = 10.0;
  // Covariance of delta = residual_sigma^2 * inverse(scan-to-map normal matrix), no direction
  // less certain than the fallback sigmas (which are also the fallback's covariance).
  double residual_sigma_m = 0.05;
  double fallback_sigma_m = 1.0;
  double fallback_sigma_deg = 5.0;
  // A map registration from the prediction is weak along a direction whose translation
  // information is below this fraction of the strongest direction's (degeneracy.hpp): its
  // standard deviation 1/sqrt(ratio) times the best one's. That direction is then checked by
  // scan-to-scan, and a disagreement with chi-square above check_chi2 (1 degree of freedom;
  // 6.63: 1 % of agreeing estimates would be taken for disagreeing) re-anchors the pose and the
  // velocity to scan-to-scan's.
  double weak_direction_ratio = 0.01;
  double check_chi2 = 6.63;
  // Scan-to-scan also checks every this many-th map registration (0: only weak ones): a wrong
  // velocity that the map itself has come to agree with would last at most this many frames.
  // Off by default: on the constructed corridor scan-to-scan from the wrong prediction agreed
  // with the wrong map registration (docs/ego.md), so it is not yet shown to help.
  int check_every_frames = 10;
  // ...and a disagreement is acted on only beyond this (m): closer, the map registration's own
  // correspondences (searched within scan_to_map.max_neighbor_distance_m, 1 m) reach the right
  // surfaces and pull it back by itself. Half that radius.
  double check_min_disagreement_m = 0.5;
  // How the scans were taken (the lidar section, not the odometry's): each scan's features are
  // moved to its reference instant before registration (lidar_odometry.cpp). 0: de-skewed scans.
  SweepTiming sweep{0.0, true};
  // ...and how far below its ray the lidar stores each point (KITTI's HDL-64E: 0.22 deg,
  // vertical_angle.hpp): the features are put back on their rays first, as IMLS-SLAM, CT-ICP and
  // KISS-ICP do with KITTI's scans. Left in, each scan's ground is a shallow cone, and the
  // registration of cones seen from places metres apart tilts the pose by a few thousandths of
  // a degree a scan, every scan the same way: 8 m of height lost over 490 m of flat road.
  double vertical_angle_error_rad = 0.0;
};

// Parses a mode name: "aloam" (no removal) or "aloam-filtered" (A-LOAM*); throws
// std::invalid_argument for anything else.
bool removesDetectedObjects(const std::string& mode);
const char* modeName(bool remove_detected_objects);

// Reads every key of the odometry section (sub-sections are finished here; the caller
// reads its own node-only keys from `section` and then calls section.finish()).
OdometryConfig readOdometryConfig(ConfigSection& section);
// The odometry's settings that describe the sensor, from the pipeline's lidar section.
void takeLidar(const LidarConfig& lidar, OdometryConfig& cfg);

}  // namespace dlslot::odometry
