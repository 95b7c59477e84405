#include "dlslot/config.hpp"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>

namespace dlslot {
namespace {

template <class T>
const char* typeName();
template <> const char* typeName<bool>() { return "true or false"; }
template <> const char* typeName<int>() { return "an integer"; }
template <> const char* typeName<double>() { return "a number"; }
template <> const char* typeName<std::string>() { return "a string"; }
template <> const char* typeName<std::vector<double>>() { return "a list of numbers"; }
template <> const char* typeName<std::vector<std::string>>() { return "a list of strings"; }

// A map key as a name. YAML allows a list, a map or nothing as a key ("? [a]: 1", "? : 1"); no
// section of ours has such keys, and yaml-cpp would throw its own exception converting one.
std::string keyName(const YAML::Node& key, const std::string& file) {
  if (!key.IsScalar())
    throw ConfigError(file + " (line " + std::to_string(key.Mark().line + 1) + "): expected a key name, got " +
                      (key.IsSequence() ? "a list" : key.IsMap() ? "a map" : "an empty key"));
  return key.Scalar();
}

}  // namespace

ConfigSection::ConfigSection(YAML::Node node, std::string file, std::string path)
    : node_(std::move(node)), file_(std::move(file)), path_(std::move(path)),
      read_(std::make_shared<std::set<std::string>>()) {}

std::string ConfigSection::where(const std::string& key) const {
  std::string full = path_.empty() ? key : path_ + "." + key;
  return file_ + ": " + full;
}

bool ConfigSection::has(const std::string& key) const { return node_.IsMap() && node_[key]; }

YAML::Node ConfigSection::child(const std::string& key, const char* expected) {
  if (!node_.IsMap() || !node_[key])
    throw ConfigError(where(key) + ": missing (expected " + expected + ")");
  read_->insert(key);
  return node_[key];
}

template <class T>
void ConfigSection::get(const std::string& key, T& out) {
  YAML::Node n = child(key, typeName<T>());
  try {
    if constexpr (std::is_same_v<T, std::string>) {
      if (!n.IsScalar()) throw YAML::Exception(n.Mark(), "");
    } else if constexpr (std::is_same_v<T, std::vector<double>> || std::is_same_v<T, std::vector<std::string>>) {
      if (!n.IsSequence()) throw YAML::Exception(n.Mark(), "");
    }
    out = n.as<T>();
    // .nan is a number to YAML but never a setting: refused like a misspelt key.
    // (.inf is a limit that is not there, e.g. a speed bound a class does not have.)
    bool number = true;
    if constexpr (std::is_same_v<T, double>) number = !std::isnan(out);
    if constexpr (std::is_same_v<T, std::vector<double>>)
      for (double v : out) number = number && !std::isnan(v);
    if (!number)
      throw ConfigError(where(key) + " (line " + std::to_string(n.Mark().line + 1) +
                        "): expected a number, got " + (n.IsScalar() ? "'" + n.Scalar() + "'" : "a list with .nan in it"));
  } catch (const YAML::Exception&) {
    std::string got = n.IsScalar() ? "'" + n.Scalar() + "'" : n.IsSequence() ? "a list" : "a map";
    throw ConfigError(where(key) + " (line " + std::to_string(n.Mark().line + 1) + "): expected " +
                      typeName<T>() + ", got " + got);
  }
}

template void ConfigSection::get<bool>(const std::string&, bool&);
template void ConfigSection::get<int>(const std::string&, int&);
template void ConfigSection::get<double>(const std::string&, double&);
template void ConfigSection::get<std::string>(const std::string&, std::string&);
template void ConfigSection::get<std::vector<double>>(const std::string&, std::vector<double>&);
template void ConfigSection::get<std::vector<std::string>>(const std::string&, std::vector<std::string>&);

ConfigSection ConfigSection::section(const std::string& key) {
  YAML::Node n = child(key, "a map");
  if (!n.IsMap())
    throw ConfigError(where(key) + " (line " + std::to_string(n.Mark().line + 1) + "): expected a map");
  return ConfigSection(n, file_, path_.empty() ? key : path_ + "." + key);
}

std::vector<std::string> ConfigSection::keys() const {
  std::vector<std::string> out;
  if (node_.IsMap())
    for (const auto& kv : node_) out.push_back(keyName(kv.first, file_));
  return out;
}

void ConfigSection::skip(const std::string& key) { read_->insert(key); }

void ConfigSection::finish() const {
  if (!node_.IsMap()) return;
  for (const auto& kv : node_) {
    const std::string key = keyName(kv.first, file_);
    if (!read_->count(key))
      throw ConfigError(where(key) + " (line " + std::to_string(kv.first.Mark().line + 1) +
                        "): unknown key");
  }
}

std::string findConfigFile(const std::string& given) {
  namespace fs = std::filesystem;
  if (given != kDefaultConfig) return given;
  if (const char* env = std::getenv("DLSLOT_CONFIG"); env && *env) return env;
  std::vector<fs::path> candidates = {fs::path(given)};
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) candidates.push_back(exe.parent_path().parent_path() / "share" / "dlslot" / given);
#ifdef DLSLOT_SOURCE_DIR
  candidates.push_back(fs::path(DLSLOT_SOURCE_DIR) / given);
#endif
  std::string looked;
  for (const fs::path& c : candidates) {
    if (fs::is_regular_file(c, ec)) return c.lexically_normal().string();
    looked += "\n  " + fs::absolute(c, ec).lexically_normal().string();
  }
  throw ConfigError(std::string(given) + ": no config file found (give --config FILE or set DLSLOT_CONFIG); looked at:" +
                    looked);
}

ConfigSection loadConfig(const std::string& given) {
  const std::string file = findConfigFile(given);
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec)) throw ConfigError(file + ": is a directory, expected a config file");
  std::cerr << "config: " << std::filesystem::absolute(file, ec).lexically_normal().string() << "\n";
  std::ifstream in(file);
  if (!in) throw ConfigError(file + ": cannot open config file");
  try {
    YAML::Node root = YAML::Load(in);
    if (!root.IsMap()) throw ConfigError(file + ": expected a YAML map at the top level");
    return ConfigSection(root, file, "");
  } catch (const YAML::Exception& e) {
    throw ConfigError(file + ":" + std::to_string(e.mark.line + 1) + ": not valid YAML: " + e.msg);
  }
}

void Channels::read(ConfigSection s) {
  s.get("scan", scan);
  s.get("detections", detections);
  s.get("ground_truth", ground_truth);
  s.get("odometry", odometry);
  s.get("associations", associations);
  s.get("slot_state", slot_state);
  s.get("status", status);
  // Optional (their defaults): configs written before the mapper and the player's events still load.
  if (s.has("map_state")) s.get("map_state", map_state);
  if (s.has("run_event")) s.get("run_event", run_event);
  const std::pair<const char*, const std::string*> all[] = {
      {"scan", &scan},           {"detections", &detections}, {"ground_truth", &ground_truth},
      {"odometry", &odometry},   {"associations", &associations}, {"slot_state", &slot_state},
      {"status", &status},       {"map_state", &map_state}, {"run_event", &run_event}};
  for (size_t i = 0; i < std::size(all); ++i) {
    if (all[i].second->empty())
      throw ConfigError(s.file() + ": " + s.path() + "." + all[i].first + ": expected a channel name, got ''");
    for (size_t j = 0; j < i; ++j)
      if (*all[i].second == *all[j].second)
        throw ConfigError(s.file() + ": " + s.path() + "." + all[i].first + ": channel '" + *all[i].second +
                          "' is already " + s.path() + "." + all[j].first + "; every channel needs a name of its own");
  }
  s.finish();
}

LidarConfig LidarConfig::read(ConfigSection s) {
  LidarConfig c;
  s.get("sweep_period_s", c.sweep.period_s);
  if (!(c.sweep.period_s >= 0 && c.sweep.period_s <= 1.0))
    throw ConfigError(s.file() + ": " + s.path() + ".sweep_period_s: expected a value in [0, 1] s (0: de-skewed scans)");
  s.get("sweep_clockwise", c.sweep.clockwise);
  double vertical_deg = 0;
  s.get("vertical_angle_error_deg", vertical_deg);
  if (!(std::abs(vertical_deg) <= 5.0))
    throw ConfigError(s.file() + ": " + s.path() + ".vertical_angle_error_deg: expected a value in [-5, 5] deg, got " +
                      std::to_string(vertical_deg));
  c.vertical_angle_error_rad = vertical_deg * M_PI / 180.0;
  s.finish();
  return c;
}

ConfigSection loadPipelineConfig(const std::string& file, Channels& channels) {
  ConfigSection root = loadConfig(file);
  for (const char* section : {"channels", "lidar", "player", "detector", "odometry", "tracker", "backend", "renderer", "mapper"})
    root.skip(section);
  root.finish();
  channels.read(root.section("channels"));
  return root;
}

}  // namespace dlslot
