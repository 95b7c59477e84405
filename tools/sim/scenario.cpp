#include "scenario.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "dlslot/config.hpp"

namespace fs = std::filesystem;

namespace dlslot::sim {
namespace {

constexpr double kDeg = M_PI / 180.0;

// A map of the scenario file: ConfigSection checks keys and types; `raw` is the same node, for
// the lists of maps (roads, pieces, traffic) ConfigSection has no accessor for.
struct Section {
  ConfigSection cfg;
  YAML::Node raw;

  Section(ConfigSection c, YAML::Node r) : cfg(std::move(c)), raw(std::move(r)) {}
  Section sub(const std::string& key) { return {cfg.section(key), raw[key]}; }
  bool has(const std::string& key) const { return cfg.has(key); }
  std::string where(const std::string& key) const {
    return cfg.file() + ": " + (cfg.path().empty() ? key : cfg.path() + "." + key);
  }
  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    const YAML::Node n = raw[key];
    const std::string line = n ? " (line " + std::to_string(n.Mark().line + 1) + ")" : "";
    throw ConfigError(where(key) + line + ": " + what);
  }
  // Elements of a list of maps, each as its own Section named key[i].
  std::vector<Section> list(const std::string& key) {
    if (!has(key)) fail(key, "missing (expected a list)");
    cfg.skip(key);
    const YAML::Node n = raw[key];
    if (!n.IsSequence()) fail(key, "expected a list");
    std::vector<Section> out;
    for (size_t i = 0; i < n.size(); ++i) {
      const std::string path = (cfg.path().empty() ? key : cfg.path() + "." + key) + "[" + std::to_string(i) + "]";
      if (!n[i].IsMap())
        throw ConfigError(cfg.file() + ": " + path + " (line " + std::to_string(n[i].Mark().line + 1) +
                          "): expected a map");
      out.emplace_back(ConfigSection(n[i], cfg.file(), path), n[i]);
    }
    return out;
  }
  template <class T>
  void optional(const std::string& key, T& out) {
    if (has(key)) cfg.get(key, out);
  }
  double positive(const std::string& key) {
    const double v = cfg.get<double>(key);
    if (!(v > 0)) fail(key, "expected a positive number, got " + std::to_string(v));
    return v;
  }
  void fraction(const std::string& key, double& out) {
    if (!has(key)) return;
    cfg.get(key, out);
    if (out < 0 || out > 1) fail(key, "expected a number in [0, 1], got " + std::to_string(out));
  }
  void interval(const std::string& key, Interval& out) {
    if (!has(key)) return;
    const auto v = cfg.get<std::vector<double>>(key);
    if (v.size() != 2 || v[0] > v[1]) fail(key, "expected [low, high] with low <= high");
    out = {v[0], v[1]};
  }
  std::vector<std::pair<double, double>> pairs(const std::string& key) {
    std::vector<std::pair<double, double>> out;
    cfg.skip(key);
    const YAML::Node n = raw[key];
    bool ok = n.IsSequence() && n.size() > 0;
    for (size_t i = 0; ok && i < n.size(); ++i) {
      ok = n[i].IsSequence() && n[i].size() == 2;
      try {
        if (ok) out.emplace_back(n[i][0].as<double>(), n[i][1].as<double>());
      } catch (const YAML::Exception&) {
        ok = false;
      }
    }
    if (!ok) fail(key, "expected a list of [a, b] number pairs");
    return out;
  }
};

RouteSpec readRoute(Section s) {
  RouteSpec r;
  const auto start = s.cfg.get<std::vector<double>>("start");
  if (start.size() != 3) s.fail("start", "expected [x, y, heading_deg]");
  r.start = {start[0], start[1]};
  r.start_heading = start[2] * kDeg;
  s.optional("transition_m", r.transition_m);
  for (Section p : s.list("pieces")) {
    RouteSpec::Piece piece;
    if (p.has("straight")) {
      piece.length_m = p.positive("straight");
    } else if (p.has("turn_deg")) {
      const double turn = p.cfg.get<double>("turn_deg") * kDeg;
      const double radius = p.positive("radius_m");
      piece.length_m = std::abs(turn) * radius;
      piece.curvature = (turn > 0 ? 1.0 : -1.0) / radius;
      if (turn == 0) p.fail("turn_deg", "expected a non-zero angle");
    } else {
      throw ConfigError(p.cfg.file() + ": " + p.cfg.path() +
                        ": expected `straight: METRES` or `turn_deg` + `radius_m`");
    }
    p.cfg.finish();
    r.pieces.push_back(piece);
  }
  if (r.pieces.empty()) s.fail("pieces", "expected at least one piece");
  s.cfg.finish();
  return r;
}

RoadsideSpec readRoadside(Section s) {
  RoadsideSpec r;
  s.optional("frontage_m", r.frontage_m);
  s.fraction("buildings", r.buildings);
  s.interval("building_length_m", r.building_length_m);
  s.interval("building_depth_m", r.building_depth_m);
  s.interval("building_height_m", r.building_height_m);
  s.fraction("walls", r.walls);
  s.optional("poles_every_m", r.poles_every_m);
  s.optional("poles_offset_m", r.poles_offset_m);
  s.optional("trees_every_m", r.trees_every_m);
  s.optional("trees_offset_m", r.trees_offset_m);
  s.optional("bushes_every_m", r.bushes_every_m);
  s.optional("guard_rail_offset_m", r.guard_rail_offset_m);
  s.optional("median_barrier", r.median_barrier);
  s.fraction("noise_walls", r.noise_walls);
  s.cfg.finish();
  return r;
}

RoadSpec readRoad(Section s) {
  RoadSpec r;
  s.cfg.get("name", r.name);
  r.route = readRoute(s.sub("route"));
  s.cfg.get("lanes", r.lanes);
  r.carriageway_m = s.positive("carriageway_m");
  r.clear_m = s.positive("clear_m");
  if (r.clear_m < r.carriageway_m) s.fail("clear_m", "expected at least carriageway_m");
  if (s.has("parking")) {
    Section p = s.sub("parking");
    ParkingSpec park;
    park.offset_m = p.positive("offset_m");
    p.interval("spacing_m", park.spacing_m);
    if (!(park.spacing_m.lo > 0)) p.fail("spacing_m", "expected positive spacings [low, high]");
    p.fraction("fill", park.fill);
    double angle_deg = 0;
    p.optional("angle_deg", angle_deg);
    park.angle = angle_deg * kDeg;
    p.cfg.finish();
    r.parking = park;
  }
  if (s.has("roadside")) r.roadside = readRoadside(s.sub("roadside"));
  s.cfg.finish();
  return r;
}

PathSpec readPath(Section& s, const std::vector<RoadSpec>& roads) {
  PathSpec p;
  auto checkRoad = [&](Section& at, const std::string& name) {
    for (const RoadSpec& r : roads)
      if (r.name == name) return;
    at.fail("road", "no road named '" + name + "'");
  };
  if (s.has("crossing")) {
    Section c = s.sub("crossing");
    c.cfg.get("road", p.road);
    checkRoad(c, p.road);
    p.crossing_s_m = c.cfg.get<double>("s_m");
    c.cfg.finish();
  } else if (s.has("route")) {
    p.route = readRoute(s.sub("route"));
    s.optional("lane", p.lane);
  } else if (s.has("road")) {
    s.cfg.get("road", p.road);
    checkRoad(s, p.road);
    s.cfg.get("lane", p.lane);
  } else {
    throw ConfigError(s.cfg.file() + ": " + s.cfg.path() + ": expected `road` + `lane`, `route` or `crossing`");
  }
  return p;
}

void readSensor(Section s, SensorSpec& o) {
  s.optional("beams", o.beams);
  if (o.beams < 2 || o.beams > 255) s.fail("beams", "expected 2..255 beams, got " + std::to_string(o.beams));
  s.optional("top_elevation_deg", o.top_elevation_deg);
  s.optional("bottom_elevation_deg", o.bottom_elevation_deg);
  if (!(o.top_elevation_deg > o.bottom_elevation_deg && o.top_elevation_deg < 90 && o.bottom_elevation_deg > -90))
    s.fail("top_elevation_deg", "expected -90 < bottom_elevation_deg < top_elevation_deg < 90");
  s.optional("azimuth_steps", o.azimuth_steps);
  if (o.azimuth_steps < 100) s.fail("azimuth_steps", "expected at least 100");
  s.optional("max_range_m", o.max_range_m);
  s.optional("min_range_m", o.min_range_m);
  s.optional("height_m", o.height_m);
  auto nonNegative = [&](const char* key, double& v) {
    s.optional(key, v);
    if (!(v >= 0)) s.fail(key, "expected a number >= 0, got " + std::to_string(v));
  };
  nonNegative("range_noise_m", o.range_noise_m);
  nonNegative("range_noise_per_100m", o.range_noise_per_100m);
  nonNegative("beam_divergence_mrad", o.beam_divergence_mrad);
  nonNegative("footprint_noise", o.footprint_noise);
  s.fraction("dropout", o.dropout);
  nonNegative("dropout_signal", o.dropout_signal);
  if (s.has("dropout_steepness")) o.dropout_steepness = s.positive("dropout_steepness");
  s.optional("azimuth_phase", o.azimuth_phase);
  nonNegative("beam_elevation_error_deg", o.beam_elevation_error_deg);
  nonNegative("beam_azimuth_error_deg", o.beam_azimuth_error_deg);
  nonNegative("beam_range_bias_m", o.beam_range_bias_m);
  s.optional("vertical_angle_error_deg", o.vertical_angle_error_deg);
  s.optional("motion_distortion", o.motion_distortion);
  s.optional("deskewed", o.deskewed);
  nonNegative("vegetation_mean_free_path_m", o.vegetation_mean_free_path_m);
  s.fraction("fences", o.fences);
  s.fraction("fence_pass", o.fence_pass);
  s.cfg.finish();
}

void readDetector(Section s, DetectorSpec& d) {
  s.optional("points_for_half", d.points_for_half);
  s.fraction("max_probability", d.max_probability);
  s.optional("position_noise_m", d.position_noise_m);
  s.optional("position_noise_per_m", d.position_noise_per_m);
  if (s.has("position_noise_across_ratio")) d.position_noise_across_ratio = s.positive("position_noise_across_ratio");
  s.optional("drift_m", d.drift_m);
  s.optional("drift_per_m", d.drift_per_m);
  if (d.drift_m < 0 || d.drift_per_m < 0) s.fail("drift_m", "expected drift_m and drift_per_m >= 0");
  s.fraction("drift_across_ratio", d.drift_across_ratio);
  if (s.has("drift_time_s")) d.drift_time_s = s.positive("drift_time_s");
  d.drift_across_time_s = s.has("drift_across_time_s") ? s.positive("drift_across_time_s") : d.drift_time_s;
  s.optional("yaw_noise_deg", d.yaw_noise);
  if (s.has("yaw_noise_deg")) d.yaw_noise *= kDeg;
  s.fraction("heading_flip", d.heading_flip);
  s.optional("size_noise", d.size_noise);
  s.optional("false_positives_per_frame", d.false_positives_per_frame);
  s.fraction("ghost_fraction", d.ghost_fraction);
  s.cfg.finish();
}

}  // namespace

Scenario loadScenario(const std::string& path) {
  ConfigSection cfg = loadConfig(path);
  YAML::Node raw = YAML::LoadFile(path);
  Section s(cfg, raw);
  Scenario sc;
  sc.file = path;
  sc.source = YAML::Clone(raw);
  s.cfg.get("name", sc.name);
  s.optional("frames", sc.frames);
  if (sc.frames < 1) s.fail("frames", "expected at least 1");
  if (s.has("seed")) {
    s.cfg.skip("seed");
    try {
      sc.seed = raw["seed"].as<uint64_t>();
    } catch (const YAML::Exception&) {
      s.fail("seed", "expected a non-negative integer");
    }
  }
  s.optional("frame_period_s", sc.frame_period_s);
  if (s.has("sensor")) readSensor(s.sub("sensor"), sc.sensor);
  if (s.has("ground")) {
    Section g = s.sub("ground");
    g.optional("max_slope", sc.ground.max_slope);
    g.interval("wavelength_m", sc.ground.wavelength_m);
    if (!(sc.ground.wavelength_m.lo > 0)) g.fail("wavelength_m", "expected positive wavelengths");
    g.cfg.finish();
  }
  for (Section r : s.list("roads")) sc.roads.push_back(readRoad(r));
  if (sc.roads.empty()) s.fail("roads", "expected at least one road (the world is built along the roads)");
  for (size_t i = 0; i < sc.roads.size(); ++i)
    for (size_t j = 0; j < i; ++j)
      if (sc.roads[i].name == sc.roads[j].name) s.fail("roads", "two roads named '" + sc.roads[i].name + "'");
  if (s.has("signals")) {
    for (Section g : s.list("signals")) {
      SignalSpec sig;
      const auto at = g.cfg.get<std::vector<double>>("at");
      if (at.size() != 2) g.fail("at", "expected [x, y]");
      sig.at = {at[0], at[1]};
      sig.radius_m = g.positive("radius_m");
      sig.axis = g.cfg.get<double>("axis_deg") * kDeg;
      for (const auto& [a, b] : g.pairs("red")) {
        if (a > b) g.fail("red", "expected [start, end] with start <= end");
        sig.red.push_back({a, b});
      }
      g.cfg.finish();
      sc.signals.push_back(sig);
    }
  }
  {
    Section e = s.sub("ego");
    sc.ego.path = readPath(e, sc.roads);
    if (sc.ego.path.crossing_s_m) e.fail("crossing", "the ego drives on a road lane or a route");
    e.optional("start_s_m", sc.ego.start_s_m);
    if (e.has("body_pitch_roll_deg")) {
      sc.ego.body_pitch_roll = e.cfg.get<double>("body_pitch_roll_deg") * kDeg;
      if (!(sc.ego.body_pitch_roll >= 0)) e.fail("body_pitch_roll_deg", "expected a number >= 0");
    }
    e.optional("body_heave_m", sc.ego.body_heave_m);
    if (!(sc.ego.body_heave_m >= 0)) e.fail("body_heave_m", "expected a number >= 0");
    e.optional("ride_full_speed_mps", sc.ego.ride_full_speed_mps);
    if (!(sc.ego.ride_full_speed_mps >= 0)) e.fail("ride_full_speed_mps", "expected a number >= 0 (0: the same ride at every speed)");
    sc.ego.speed_profile = e.pairs("speed_mps");
    for (size_t i = 1; i < sc.ego.speed_profile.size(); ++i)
      if (sc.ego.speed_profile[i].first <= sc.ego.speed_profile[i - 1].first)
        e.fail("speed_mps", "expected increasing times");
    for (const auto& knot : sc.ego.speed_profile)
      if (knot.second < 0) e.fail("speed_mps", "expected speeds >= 0");
    e.cfg.finish();
  }
  if (s.has("traffic")) {
    for (Section t : s.list("traffic")) {
      TrafficSpec tr;
      tr.path = readPath(t, sc.roads);
      t.cfg.skip("classes");
      const YAML::Node classes = t.raw["classes"];
      if (!classes || !classes.IsMap() || classes.size() == 0) t.fail("classes", "expected a map CLASS: weight");
      for (const auto& kv : classes) {
        const std::string name = kv.first.as<std::string>();
        static const char* kKnown[] = {"Car", "Van", "Truck", "Cyclist", "Pedestrian"};
        if (std::find(std::begin(kKnown), std::end(kKnown), name) == std::end(kKnown))
          t.fail("classes", "unknown class '" + name + "' (expected Car, Van, Truck, Cyclist or Pedestrian)");
        double w = 0;
        try {
          w = kv.second.as<double>();
        } catch (const YAML::Exception&) {
          w = -1;
        }
        if (!(w > 0)) t.fail("classes", "weight of '" + name + "': expected a positive number");
        tr.classes[name] = w;
      }
      t.cfg.get("count", tr.count);
      if (tr.count < 0) t.fail("count", "expected >= 0");
      t.interval("start_s_m", tr.start_s_m);
      t.interval("speed_mps", tr.speed_mps);
      if (!t.has("speed_mps")) t.fail("speed_mps", "missing (expected [low, high])");
      t.interval("start_time_s", tr.start_time_s);
      t.optional("speed_changes", tr.speed_changes);
      t.fraction("stop_probability", tr.stop_probability);
      t.cfg.finish();
      sc.traffic.push_back(tr);
    }
  }
  if (s.has("labels")) {
    Section l = s.sub("labels");
    l.optional("min_points", sc.labels.min_points);
    l.cfg.finish();
  }
  if (s.has("detector")) readDetector(s.sub("detector"), sc.detector);
  s.cfg.finish();
  return sc;
}

std::string resolveScenario(const std::string& name_or_path, const std::string& source_dir) {
  if (fs::is_regular_file(name_or_path)) return name_or_path;
  // An installed dlslot-sim finds the scenarios installed beside it (PREFIX/share/dlslot), a
  // built one those of its source tree.
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const fs::path installed =
        exe.parent_path().parent_path() / "share" / "dlslot" / "config" / "scenarios" / (name_or_path + ".yaml");
    if (fs::is_regular_file(installed, ec)) return installed.string();
  }
  const fs::path named = fs::path(source_dir) / "config" / "scenarios" / (name_or_path + ".yaml");
  if (fs::is_regular_file(named)) return named.string();
  std::vector<std::string> names;
  if (fs::is_directory(named.parent_path()))
    for (const auto& e : fs::directory_iterator(named.parent_path()))
      if (e.path().extension() == ".yaml") names.push_back(e.path().stem().string());
  std::sort(names.begin(), names.end());
  std::string known;
  for (const std::string& n : names) known += (known.empty() ? "" : ", ") + n;
  throw ConfigError("scenario '" + name_or_path + "': no such file and no " + named.string() +
                    (known.empty() ? "" : " (known scenarios: " + known + ")"));
}

void writeScenario(const std::string& path, const Scenario& scenario) {
  YAML::Node out = YAML::Clone(scenario.source);
  out["frames"] = scenario.frames;
  out["seed"] = scenario.seed;
  std::ofstream f(path);
  if (!f) throw ConfigError(path + ": cannot open for writing");
  f << "# The scenario this sequence was made from (" << scenario.file << "), with the seed and frame count used.\n"
    << out << "\n";
  f.close();
  if (!f) throw ConfigError(path + ": writing failed");
}

}  // namespace dlslot::sim
