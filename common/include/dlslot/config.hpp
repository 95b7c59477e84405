// YAML configuration with errors that name the file, the key and what was expected.
// Every key a process knows must be present (the shipped config/dlslot.yaml has them all), and
// a key nobody reads is an error too, so a typo never silently falls back to a default.
#pragma once

#include <yaml-cpp/yaml.h>

#include <memory>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "dlslot/sweep_timing.hpp"

namespace dlslot {

class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class ConfigSection {
 public:
  ConfigSection(YAML::Node node, std::string file, std::string path);

  // Required key of type T (bool, int, double, std::string, std::vector<double>, std::vector<std::string>).
  template <class T>
  void get(const std::string& key, T& out);
  template <class T>
  T get(const std::string& key) {
    T v{};
    get(key, v);
    return v;
  }
  bool has(const std::string& key) const;
  // The keys of this section, in file order (for maps whose keys are names, e.g. classes).
  std::vector<std::string> keys() const;
  ConfigSection section(const std::string& key);
  // Throws ConfigError for every key of this section that was never read.
  void finish() const;
  // Marks a key read without reading it (for sections another process owns).
  void skip(const std::string& key);

  const std::string& file() const { return file_; }
  const std::string& path() const { return path_; }

 private:
  YAML::Node child(const std::string& key, const char* expected);
  std::string where(const std::string& key) const;

  YAML::Node node_;
  std::string file_, path_;
  std::shared_ptr<std::set<std::string>> read_;
};

// The shipped config's path relative to the source tree, and every tool's default --config.
inline constexpr const char* kDefaultConfig = "config/dlslot.yaml";

// The config file to load for `given` (a --config value). Any path other than the default is
// used as given. For the default: $DLSLOT_CONFIG when set, else config/dlslot.yaml in the working
// directory, else the one of the install (<prefix>/share/dlslot/, next to the executable's bin/)
// or of the source tree the binaries were built from. So a binary works from any directory.
// Throws ConfigError saying where it looked.
std::string findConfigFile(const std::string& given = kDefaultConfig);

// Loads a YAML file (found with findConfigFile and named on stderr); throws ConfigError naming
// the file when it is missing or not YAML.
ConfigSection loadConfig(const std::string& file);

// Channel names, one place (config section `channels`).
struct Channels {
  std::string scan = "LIDAR_SCAN";
  std::string detections = "DETECTIONS";
  std::string ground_truth = "GROUND_TRUTH";
  std::string odometry = "ODOMETRY";
  std::string associations = "ASSOCIATIONS";
  std::string slot_state = "SLOT_STATE";
  std::string status = "PROCESS_STATUS";
  std::string map_state = "MAP_STATE";  // optional key: the mapper's loop-closure correction and events
  std::string run_event = "RUN_EVENT";  // optional key (the player's start events)
  // Reads the section; every channel must have a name of its own: two roles on one channel (e.g.
  // odometry: SLOT_STATE) would feed one process's output to another as a different type.
  void read(ConfigSection section);
};

// How the scans were taken (section `lidar`): properties of the data, one place for every process
// that uses raw points (the back end's object registration, the mapper, dlslot-eval --map).
struct LidarConfig {
  SweepTiming sweep;                      // sweep_period_s (0: de-skewed scans), sweep_clockwise
  double vertical_angle_error_rad = 0.0;  // vertical_angle_error_deg: how far below its ray each point is stored
  static LidarConfig read(ConfigSection section);
};

// Loads the pipeline's one config file for a process: every top-level key must be one of the
// known sections (a misspelt section name is an error, not a block silently ignored), and the
// channel names are read into `channels`. Returns the root, from which the process reads its
// own section.
ConfigSection loadPipelineConfig(const std::string& file, Channels& channels);

}  // namespace dlslot
