#include "odometry_config.hpp"

#include <cmath>
#include <stdexcept>

namespace dlslot::odometry {

bool removesDetectedObjects(const std::string& mode) {
  if (mode == "aloam") return false;
  if (mode == "aloam-filtered") return true;
  throw std::invalid_argument("odometry mode '" + mode + "': expected aloam or aloam-filtered");
}

const char* modeName(bool remove_detected_objects) { return remove_detected_objects ? "aloam-filtered" : "aloam"; }

namespace {

void readSolver(ConfigSection s, SolverConfig& c) {
  s.get("outer_iterations", c.outer_iterations);
  s.get("solver_iterations", c.solver_iterations);
  s.get("huber_delta_m", c.huber_delta_m);
  s.get("converged_step_m", c.converged_step_m);
  s.get("converged_step_deg", c.converged_step_deg);
  s.finish();
}

void readFeatures(ConfigSection s, FeatureConfig& c) {
  s.get("beam_model", c.beam_model);
  if (c.beam_model != "hdl64" && c.beam_model != "uniform")
    throw ConfigError(s.file() + ": " + s.path() + ".beam_model: expected hdl64 or uniform, got '" + c.beam_model + "'");
  s.get("num_beams", c.num_beams);
  s.get("min_vertical_deg", c.min_vertical_deg);
  s.get("max_vertical_deg", c.max_vertical_deg);
  s.get("min_range_m", c.min_range_m);
  s.get("curvature_half_window", c.curvature_half_window);
  s.get("max_azimuth_gap_deg", c.max_azimuth_gap_deg);
  s.get("sectors_per_beam", c.sectors_per_beam);
  s.get("edge_curvature_min", c.edge_curvature_min);
  s.get("plane_curvature_max", c.plane_curvature_max);
  s.get("sharp_per_sector", c.sharp_per_sector);
  s.get("less_sharp_per_sector", c.less_sharp_per_sector);
  s.get("flat_per_sector", c.flat_per_sector);
  s.get("suppression_half_window", c.suppression_half_window);
  s.get("suppression_max_gap_m", c.suppression_max_gap_m);
  s.get("less_flat_spacing_m", c.less_flat_spacing_m);
  s.finish();
  if (c.num_beams < 1 || c.curvature_half_window < 1 || c.sectors_per_beam < 1 ||
      c.max_vertical_deg <= c.min_vertical_deg)
    throw ConfigError(s.file() + ": " + s.path() +
                      ": expected num_beams, curvature_half_window, sectors_per_beam >= 1 and "
                      "max_vertical_deg > min_vertical_deg");
}

void readScanToScan(ConfigSection s, ScanToScanConfig& c) {
  s.get("every_scan", c.every_scan);
  readSolver(s.section("solver"), c.solver);
  s.get("max_match_distance_m", c.max_match_distance_m);
  s.get("nearby_beams", c.nearby_beams);
  s.get("candidates", c.candidates);
  s.get("min_correspondences", c.min_correspondences);
  s.get("max_forward_m", c.max_forward_m);
  s.get("hypothesis_spacing_m", c.hypothesis_spacing_m);
  s.finish();
  if (c.candidates < 3 || !(c.max_forward_m >= 0.0) || !(c.hypothesis_spacing_m > 0.0) ||
      c.max_forward_m / c.hypothesis_spacing_m > 1000.0)
    throw ConfigError(s.file() + ": " + s.path() +
                      ": expected candidates >= 3, max_forward_m >= 0 and 0 < hypothesis_spacing_m with at most "
                      "1000 hypotheses up to max_forward_m");
}

void readScanToMap(ConfigSection s, ScanToMapConfig& c) {
  readSolver(s.section("solver"), c.solver);
  s.get("edge_voxel_m", c.edge_voxel_m);
  s.get("plane_voxel_m", c.plane_voxel_m);
  s.get("neighbors", c.neighbors);
  s.get("max_neighbor_distance_m", c.max_neighbor_distance_m);
  s.get("edge_eigen_ratio", c.edge_eigen_ratio);
  s.get("edge_max_tilt_deg", c.edge_max_tilt_deg);
  s.get("plane_max_deviation_m", c.plane_max_deviation_m);
  s.get("map_radius_m", c.map_radius_m);
  s.get("min_correspondences", c.min_correspondences);
  s.finish();
  if (c.neighbors < 3 || c.edge_voxel_m <= 0 || c.plane_voxel_m <= 0)
    throw ConfigError(s.file() + ": " + s.path() + ": expected neighbors >= 3 and positive voxel sizes");
}

}  // namespace

void takeLidar(const LidarConfig& lidar, OdometryConfig& cfg) {
  cfg.sweep = lidar.sweep;
  cfg.vertical_angle_error_rad = lidar.vertical_angle_error_rad;
}

OdometryConfig readOdometryConfig(ConfigSection& s) {
  OdometryConfig c;
  std::string mode;
  s.get("mode", mode);
  try {
    c.remove_detected_objects = removesDetectedObjects(mode);
  } catch (const std::invalid_argument& e) {
    throw ConfigError(s.file() + ": " + s.path() + ".mode: " + e.what());
  }
  s.get("box_margin_m", c.box_margin_m);
  s.get("ground_clearance_m", c.ground_clearance_m);
  if (!(c.box_margin_m >= 0.0) || !std::isfinite(c.ground_clearance_m))
    throw ConfigError(s.file() + ": " + s.path() + ": expected box_margin_m >= 0 and a finite ground_clearance_m");
  s.get("min_points", c.min_points);
  s.get("min_edge_features", c.min_edge_features);
  s.get("min_plane_features", c.min_plane_features);
  s.get("max_correction_m", c.max_correction_m);
  s.get("max_correction_deg", c.max_correction_deg);
  s.get("residual_sigma_m", c.residual_sigma_m);
  s.get("fallback_sigma_m", c.fallback_sigma_m);
  s.get("fallback_sigma_deg", c.fallback_sigma_deg);
  s.get("weak_direction_ratio", c.weak_direction_ratio);
  s.get("check_chi2", c.check_chi2);
  s.get("check_every_frames", c.check_every_frames);
  s.get("check_min_disagreement_m", c.check_min_disagreement_m);
  if (c.check_every_frames < 0 || !(c.check_min_disagreement_m >= 0.0))
    throw ConfigError(s.file() + ": " + s.path() + ": expected check_every_frames >= 0 and check_min_disagreement_m >= 0");
  if (!(c.weak_direction_ratio >= 0.0 && c.weak_direction_ratio < 1.0) || !(c.check_chi2 > 0.0))
    throw ConfigError(s.file() + ": " + s.path() + ": expected 0 <= weak_direction_ratio < 1 and check_chi2 > 0");
  readFeatures(s.section("features"), c.features);
  readScanToScan(s.section("scan_to_scan"), c.scan_to_scan);
  readScanToMap(s.section("scan_to_map"), c.scan_to_map);
  return c;
}

}  // namespace dlslot::odometry
