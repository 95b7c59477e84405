// How the renderer draws: the view (ego-centred or world-fixed, scale, size, layers), when a
// frame is drawn, and the whole-run summary. A plain struct with defaults; the node fills it from
// the `renderer` section of config/dlslot.yaml.
#pragma once

#include <Eigen/Core>
#include <string>

#include "dlslot/config.hpp"

namespace dlslot::renderer {

// Which layers to draw; each can be switched off in the config's `layers` list.
struct Layers {
  bool grid = true;            // range rings (ego view) or a metric grid (world view)
  bool points = true;          // scan points kept for odometry, shaded by height
  bool removed_points = true;  // scan points inside detections: removed as dynamic (paper III-D)
  bool ground_truth = true;    // labelled boxes
  bool detections = true;
  bool associations = true;    // predicted trajectory positions (eq. 3) linked to their detection
  bool tracks = true;          // optimized objects: boxes, id labels, velocity arrows
  bool track_trails = true;    // each track's recent positions
  bool trajectories = true;    // ego paths: odometry, DL-SLOT, ground truth
  bool legend = true;
  bool scale_bar = true;
  bool text = true;  // frame index, time, counts, per-module timings
};
// The names used in the config, in drawing order; throws ConfigError for an unknown name.
Layers layersFromNames(const std::vector<std::string>& names, const std::string& where);

struct ViewConfig {
  enum class Mode { Ego, World } mode = Mode::Ego;
  bool heading_up = true;  // ego mode: lidar +x points up; false: world axes, centred on the ego
  Eigen::Vector2d world_center = Eigen::Vector2d::Zero();  // world mode: world x y at the image centre
  double metres_per_pixel = 0.1;
  int width = 1000, height = 1000;
  Layers layers;
  // Points inside a detection's removal volume count as removed: the odometry's box margin and
  // ground clearance (odometry.box_margin_m, ground_clearance_m), so the image shows exactly
  // what A-LOAM* discarded.
  double removal_margin_m = 0.3;
  double removal_ground_clearance_m = 0.25;
  double min_height_m = -2.5, max_height_m = 1.5;  // lidar z mapped to the ends of the colour ramp
  double velocity_arrow_s = 1.0;                   // an arrow shows where a track is after this long
};

struct SummaryConfig {
  bool enabled = true;
  int width = 1600, height = 1200;
  double map_cell_m = 0.2;   // accumulated map of kept points; 0 = no map layer
  int map_point_stride = 4;  // every n-th point goes into the map
  double map_min_height_m = -1.4;  // lidar z; lower points are ground, left out so structure shows
};

struct RendererConfig {
  ViewConfig view;
  SummaryConfig summary;
  // A frame is drawn when its SLOT_STATE arrives, or when data of a frame this many frames newer
  // arrives, or when nothing arrived for frame_timeout_s, with whatever layers are there.
  int max_pending_frames = 1;
  double frame_timeout_s = 1.0;
  int trail_frames = 30;    // how many past positions a track's trail shows
  int png_compression = -1;  // -1: fastest encoding (~20 ms a 1000x1000 frame); 0-9: zlib level, smaller, slower
};

// Reads the `renderer` section of the config file's root, and the odometry's box margin from
// the `odometry` section; every key is required (see config/dlslot.yaml).
RendererConfig readRendererConfig(ConfigSection root);

}  // namespace dlslot::renderer
