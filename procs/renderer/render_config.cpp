#include "render_config.hpp"

namespace dlslot::renderer {
namespace {

void checkPositive(double v, const ConfigSection& s, const std::string& key) {
  if (!(v > 0)) throw ConfigError(s.file() + ": " + s.path() + "." + key + ": expected a positive number");
}

}  // namespace

Layers layersFromNames(const std::vector<std::string>& names, const std::string& where) {
  Layers l;
  const std::pair<const char*, bool Layers::*> table[] = {
      {"grid", &Layers::grid},
      {"points", &Layers::points},
      {"removed_points", &Layers::removed_points},
      {"ground_truth", &Layers::ground_truth},
      {"detections", &Layers::detections},
      {"associations", &Layers::associations},
      {"tracks", &Layers::tracks},
      {"track_trails", &Layers::track_trails},
      {"trajectories", &Layers::trajectories},
      {"legend", &Layers::legend},
      {"scale_bar", &Layers::scale_bar},
      {"text", &Layers::text},
  };
  for (const auto& entry : table) l.*entry.second = false;
  for (const std::string& name : names) {
    bool found = false;
    for (const auto& [n, member] : table)
      if (name == n) {
        l.*member = true;
        found = true;
      }
    if (!found) {
      std::string known;
      for (const auto& entry : table) known += std::string(known.empty() ? "" : ", ") + entry.first;
      throw ConfigError(where + ": unknown layer '" + name + "' (expected some of: " + known + ")");
    }
  }
  return l;
}

RendererConfig readRendererConfig(ConfigSection root) {
  RendererConfig c;
  {
    ConfigSection odometry = root.section("odometry");  // the odometry's own removal volume
    odometry.get("box_margin_m", c.view.removal_margin_m);
    odometry.get("ground_clearance_m", c.view.removal_ground_clearance_m);
  }
  ConfigSection s = root.section("renderer");
  {
    ConfigSection v = s.section("view");
    const std::string mode = v.get<std::string>("mode");
    if (mode == "ego")
      c.view.mode = ViewConfig::Mode::Ego;
    else if (mode == "world")
      c.view.mode = ViewConfig::Mode::World;
    else
      throw ConfigError(v.file() + ": " + v.path() + ".mode: expected ego or world, got '" + mode + "'");
    v.get("heading_up", c.view.heading_up);
    const auto centre = v.get<std::vector<double>>("world_center");
    if (centre.size() != 2)
      throw ConfigError(v.file() + ": " + v.path() + ".world_center: expected [x, y] in metres");
    c.view.world_center = Eigen::Vector2d(centre[0], centre[1]);
    v.get("metres_per_pixel", c.view.metres_per_pixel);
    checkPositive(c.view.metres_per_pixel, v, "metres_per_pixel");
    v.get("width", c.view.width);
    v.get("height", c.view.height);
    if (c.view.width < 200 || c.view.height < 200)
      throw ConfigError(v.file() + ": " + v.path() + ": width and height must be at least 200 pixels");
    c.view.layers = layersFromNames(v.get<std::vector<std::string>>("layers"), v.file() + ": " + v.path() + ".layers");
    const auto heights = v.get<std::vector<double>>("height_range_m");
    if (heights.size() != 2 || !(heights[0] < heights[1]))
      throw ConfigError(v.file() + ": " + v.path() + ".height_range_m: expected [low, high] with low < high");
    c.view.min_height_m = heights[0];
    c.view.max_height_m = heights[1];
    v.get("velocity_arrow_s", c.view.velocity_arrow_s);
    v.finish();
  }
  {
    ConfigSection m = s.section("summary");
    m.get("enabled", c.summary.enabled);
    m.get("width", c.summary.width);
    m.get("height", c.summary.height);
    if (c.summary.width < 200 || c.summary.height < 200)
      throw ConfigError(m.file() + ": " + m.path() + ": width and height must be at least 200 pixels");
    m.get("map_cell_m", c.summary.map_cell_m);
    m.get("map_point_stride", c.summary.map_point_stride);
    if (c.summary.map_point_stride < 1)
      throw ConfigError(m.file() + ": " + m.path() + ".map_point_stride: expected an integer >= 1");
    m.get("map_min_height_m", c.summary.map_min_height_m);
    m.finish();
  }
  s.get("max_pending_frames", c.max_pending_frames);
  if (c.max_pending_frames < 1)
    throw ConfigError(s.file() + ": " + s.path() + ".max_pending_frames: expected an integer >= 1");
  s.get("frame_timeout_s", c.frame_timeout_s);
  checkPositive(c.frame_timeout_s, s, "frame_timeout_s");
  s.get("trail_frames", c.trail_frames);
  s.get("png_compression", c.png_compression);
  if (c.png_compression < -1 || c.png_compression > 9)
    throw ConfigError(s.file() + ": " + s.path() + ".png_compression: expected -1 (fastest) or a zlib level 0-9");
  s.finish();
  return c;
}

}  // namespace dlslot::renderer
