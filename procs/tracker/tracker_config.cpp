#include "tracker_config.hpp"

#include <stdexcept>

namespace dlslot::tracker {

TrackOutput trackOutputFromName(const std::string& name) {
  if (name == "confirmed") return TrackOutput::Confirmed;
  if (name == "all") return TrackOutput::All;
  throw std::invalid_argument("output: expected 'confirmed' or 'all', got '" + name + "'");
}

namespace {

ClassPolicy readPolicy(const std::string& name, ConfigSection s, ClassPlausibility& plausible) {
  ClassPolicy p;
  p.name = name;
  s.get("types", p.types);
  s.get("min_score", p.min_score);
  s.get("min_score_to_extend", p.min_score_to_extend);
  s.get("gate_across_m", p.gate_across_m);
  s.get("gate_along_m", p.gate_along_m);
  s.get("young_gate_m", p.young_gate_m);
  s.get("gate_growth_mps", p.gate_growth_mps);
  s.get("min_hits", p.min_hits);
  s.get("max_misses", p.max_misses);
  s.get("max_polynomial_degree", p.max_polynomial_degree);
  s.get("output_coasting_frames", p.output_coasting_frames);
  s.get("moving_evidence", p.moving_evidence);
  s.get("max_speed_mps", plausible.max_speed_mps);  // .inf: no limit
  s.get("too_fast_type", plausible.too_fast_type);
  s.get("yields_to_other_classes", plausible.yields_to_other_classes);
  s.finish();
  if (!(plausible.max_speed_mps > 0))
    throw ConfigError(s.file() + ": " + s.path() + ".max_speed_mps: expected > 0 (.inf for no limit), got " +
                      std::to_string(plausible.max_speed_mps));
  return p;
}

}  // namespace

TrackerConfig TrackerConfig::read(ConfigSection s) {
  TrackerConfig c;
  AssociatorConfig& a = c.associator;
  s.get("window_frames", a.window_frames);
  s.get("init_observations", a.init_observations);
  s.get("max_noise_gain", a.max_noise_gain);
  s.get("dynamic_displacement_m", a.dynamic_displacement_m);
  s.get("duplicate_margin_m", a.duplicate_margin_m);
  s.get("join_timeout_s", c.join_timeout_s);
  const std::string predictor = s.get<std::string>("predictor");
  const std::string score_scale = s.get<std::string>("score_scale");
  const std::string output = s.get<std::string>("output");
  ConfigSection classes = s.section("classes");
  a.classes.clear();
  for (const std::string& name : classes.keys())
    a.classes.push_back(readPolicy(name, classes.section(name), a.plausibility[name]));
  classes.finish();
  s.finish();
  try {
    a.predictor = predictorFromName(predictor);
    a.score_scale = scoreScaleFromName(score_scale);
    c.output = trackOutputFromName(output);
    if (a.classes.empty()) throw std::invalid_argument("classes: expected at least one class");
    a.validate();
    if (!(c.join_timeout_s > 0)) throw std::invalid_argument("join_timeout_s: expected > 0");
  } catch (const std::invalid_argument& e) {
    throw ConfigError(s.file() + ": " + s.path() + "." + e.what());
  }
  return c;
}

}  // namespace dlslot::tracker
