#include "speed_guard.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "dlslot/timing_stats.hpp"

namespace dlslot::run {
namespace {

double number(const YAML::Node& n, const std::string& where, const std::string& key) {
  if (!n || !n.IsScalar()) throw std::invalid_argument(where + ": " + key + ": expected a number");
  try {
    const double v = n.as<double>();
    if (!std::isfinite(v) || v < 0) throw std::invalid_argument("");
    return v;
  } catch (const std::exception&) {
    throw std::invalid_argument(where + ": " + key + ": expected a number >= 0, got '" + n.Scalar() + "'");
  }
}

}  // namespace

SpeedFigures speedFromYaml(const YAML::Node& node, const std::string& where) {
  if (!node || !node.IsMap()) throw std::invalid_argument(where + ": expected a map");
  SpeedFigures f;
  const YAML::Node cpu = node["cpu_ms_per_frame"];
  if (!cpu || !cpu.IsMap() || cpu.size() == 0)
    throw std::invalid_argument(where + ": cpu_ms_per_frame: expected a map of process: milliseconds");
  for (const auto& kv : cpu) {
    const std::string p = kv.first.as<std::string>();
    f.cpu_ms[p] = number(kv.second, where, "cpu_ms_per_frame." + p);
  }
  f.rate_fps = number(node["rate_fps"], where, "rate_fps");
  if (const YAML::Node load = node["load"]; load && load.IsSequence())
    for (size_t i = 0; i < load.size(); ++i) f.load.push_back(load[i].as<double>());
  return f;
}

SpeedFigures medianOf(const std::vector<SpeedFigures>& runs) {
  SpeedFigures out;
  if (runs.empty()) return out;
  std::map<std::string, std::vector<double>> cpu;
  std::vector<double> rates;
  for (const SpeedFigures& r : runs) {
    for (const auto& [p, ms] : r.cpu_ms) cpu[p].push_back(ms);
    rates.push_back(r.rate_fps);
  }
  for (auto& [p, v] : cpu) out.cpu_ms[p] = median(v);
  out.rate_fps = median(rates);
  out.load = runs.front().load;
  return out;
}

SpeedVerdict compareSpeed(const SpeedFigures& stored, const SpeedFigures& measured, double tolerance,
                          double floor_ms) {
  SpeedVerdict v;
  char line[200];
  for (const auto& [p, was] : stored.cpu_ms) {
    const auto it = measured.cpu_ms.find(p);
    if (it == measured.cpu_ms.end()) {
      v.over.push_back(p);
      std::snprintf(line, sizeof line, "  %-10s not measured (stored %.2f ms)  FAILED\n", p.c_str(), was);
      v.report += line;
      continue;
    }
    const double now = it->second;
    const double limit = std::max(was * (1 + tolerance), was + floor_ms);
    const bool over = now > limit;
    if (over) v.over.push_back(p);
    std::snprintf(line, sizeof line, "  %-10s %7.2f ms a frame, stored %7.2f (%+5.1f %%), limit %7.2f%s\n", p.c_str(),
                  now, was, was > 0 ? 100 * (now / was - 1) : 0.0, limit, over ? "  FAILED" : "");
    v.report += line;
  }
  for (const auto& [p, now] : measured.cpu_ms)
    if (!stored.cpu_ms.count(p)) {
      std::snprintf(line, sizeof line, "  %-10s %7.2f ms a frame, not in the baseline (not judged)\n", p.c_str(), now);
      v.report += line;
    }
  return v;
}

}  // namespace dlslot::run
