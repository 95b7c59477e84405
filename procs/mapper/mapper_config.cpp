#include "mapper/mapper_config.hpp"

#include <cmath>

namespace dlslot::mapper {
namespace {

void positive(const ConfigSection& s, const std::string& key, double v) {
  if (!(v > 0)) throw ConfigError(s.file() + ": " + s.path() + "." + key + ": expected a value > 0, got " + std::to_string(v));
}

}  // namespace

MapperConfig MapperConfig::read(ConfigSection& s) {
  MapperConfig c;
  s.get("keyframe_distance_m", c.keyframe_distance_m);
  s.get("keyframe_angle_deg", c.keyframe_angle_deg);
  s.get("min_range_m", c.min_range_m);
  s.get("max_range_m", c.max_range_m);
  s.get("map_voxel_m", c.map_voxel_m);
  std::string remove;
  s.get("remove", remove);
  if (remove != "dynamic" && remove != "movable")
    throw ConfigError(s.file() + ": " + s.path() + ".remove: expected dynamic or movable, got '" + remove + "'");
  c.remove_movable = remove == "movable";
  s.get("box_margin_m", c.box_margin_m);
  s.get("ground_clearance_m", c.ground_clearance_m);
  s.get("min_new_fraction", c.min_new_fraction);
  s.get("decision_delay_frames", c.decision_delay_frames);
  s.get("follow_frames", c.follow_frames);
  s.get("join_timeout_s", c.join_timeout_s);
  s.get("max_backlog_keyframes", c.max_backlog_keyframes);
  s.get("idle_priority", c.idle_priority);
  s.get("live_cpu_share", c.live_cpu_share);
  if (!(c.live_cpu_share > 0 && c.live_cpu_share <= 1))
    throw ConfigError(s.file() + ": " + s.path() + ".live_cpu_share: expected a share of one core in (0, 1], got " +
                      std::to_string(c.live_cpu_share));
  if (c.max_backlog_keyframes < 1)
    throw ConfigError(s.file() + ": " + s.path() + ".max_backlog_keyframes: expected >= 1, got " +
                      std::to_string(c.max_backlog_keyframes));
  for (const auto& [k, v] : {std::pair<const char*, double>{"keyframe_distance_m", c.keyframe_distance_m},
                             {"keyframe_angle_deg", c.keyframe_angle_deg},
                             {"max_range_m", c.max_range_m},
                             {"map_voxel_m", c.map_voxel_m},
                             {"join_timeout_s", c.join_timeout_s}})
    positive(s, k, v);
  if (!(c.min_range_m >= 0 && c.min_range_m < c.max_range_m))
    throw ConfigError(s.file() + ": " + s.path() + ".min_range_m: expected 0 <= min_range_m < max_range_m");
  if (!(c.min_new_fraction >= 0 && c.min_new_fraction <= 1))
    throw ConfigError(s.file() + ": " + s.path() + ".min_new_fraction: expected a value in [0, 1]");
  if (!(c.ground_clearance_m >= 0 && c.ground_clearance_m < 1.0))
    throw ConfigError(s.file() + ": " + s.path() + ".ground_clearance_m: expected a value in [0, 1) m");
  if (!(c.box_margin_m >= 0)) throw ConfigError(s.file() + ": " + s.path() + ".box_margin_m: expected a value >= 0");
  if (c.decision_delay_frames < 0 || c.follow_frames < 0)
    throw ConfigError(s.file() + ": " + s.path() + ": decision_delay_frames and follow_frames: expected >= 0");

  ConfigSection l = s.section("loop");
  LoopConfig& L = c.loop;
  l.get("enabled", L.enabled);
  l.get("correct_clouds", L.correct_clouds);
  l.get("rings", L.rings);
  l.get("sectors", L.sectors);
  l.get("max_radius_m", L.max_radius_m);
  l.get("min_separation_m", L.min_separation_m);
  l.get("search_radius_m", L.search_radius_m);
  l.get("max_descriptor_distance", L.max_descriptor_distance);
  l.get("registration_voxel_m", L.registration_voxel_m);
  l.get("coarse_correspondence_m", L.coarse_correspondence_m);
  l.get("max_correspondence_m", L.max_correspondence_m);
  l.get("fine_correspondence_m", L.fine_correspondence_m);
  l.get("submap_keyframes", L.submap_keyframes);
  l.get("overlap_radius_m", L.overlap_radius_m);
  l.get("inlier_distance_m", L.inlier_distance_m);
  l.get("support_distance_m", L.support_distance_m);
  l.get("min_inlier_ratio", L.min_inlier_ratio);
  l.get("max_rmse_m", L.max_rmse_m);
  l.get("max_drift_fraction", L.max_drift_fraction);
  l.get("ambiguity_shift_m", L.ambiguity_shift_m);
  l.get("ambiguity_ratio", L.ambiguity_ratio);
  l.get("false_loop_m", L.false_loop_m);
  l.get("start_step_m", L.start_step_m);
  l.get("start_steps", L.start_steps);
  l.get("quiet_keyframes", L.quiet_keyframes);
  l.get("odometry_sigma_t", L.odometry_sigma_t);
  l.get("odometry_sigma_r", L.odometry_sigma_r);
  l.get("loop_sigma_t", L.loop_sigma_t);
  l.get("loop_sigma_r", L.loop_sigma_r);
  if (L.start_steps < 0) throw ConfigError(l.file() + ": mapper.loop.start_steps: expected >= 0");
  if (L.quiet_keyframes < 0) throw ConfigError(l.file() + ": mapper.loop.quiet_keyframes: expected >= 0");
  if (L.submap_keyframes < 0) throw ConfigError(l.file() + ": mapper.loop.submap_keyframes: expected >= 0");
  if (L.rings < 2 || L.sectors < 4)
    throw ConfigError(l.file() + ": mapper.loop: rings >= 2 and sectors >= 4 expected");
  for (const auto& [k, v] : {std::pair<const char*, double>{"max_radius_m", L.max_radius_m},
                             {"search_radius_m", L.search_radius_m},
                             {"max_descriptor_distance", L.max_descriptor_distance},
                             {"registration_voxel_m", L.registration_voxel_m},
                             {"coarse_correspondence_m", L.coarse_correspondence_m},
                             {"max_correspondence_m", L.max_correspondence_m},
                             {"fine_correspondence_m", L.fine_correspondence_m},
                             {"inlier_distance_m", L.inlier_distance_m},
                             {"support_distance_m", L.support_distance_m},
                             {"overlap_radius_m", L.overlap_radius_m},
                             {"min_inlier_ratio", L.min_inlier_ratio},
                             {"max_rmse_m", L.max_rmse_m},
                             {"ambiguity_shift_m", L.ambiguity_shift_m},
                             {"ambiguity_ratio", L.ambiguity_ratio},
                             {"false_loop_m", L.false_loop_m},
                             {"start_step_m", L.start_step_m},
                             {"odometry_sigma_t", L.odometry_sigma_t},
                             {"odometry_sigma_r", L.odometry_sigma_r},
                             {"loop_sigma_t", L.loop_sigma_t},
                             {"loop_sigma_r", L.loop_sigma_r}})
    positive(l, k, v);
  if (!(L.support_distance_m > L.inlier_distance_m))
    throw ConfigError(l.file() + ": mapper.loop.support_distance_m: expected > inlier_distance_m");
  if (!(L.min_separation_m >= 0 && L.max_drift_fraction >= 0))
    throw ConfigError(l.file() + ": mapper.loop: min_separation_m and max_drift_fraction: expected >= 0");
  l.finish();
  return c;
}

}  // namespace dlslot::mapper
