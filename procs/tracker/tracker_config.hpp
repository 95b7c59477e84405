// The tracker's settings: the `tracker` section of config/dlslot.yaml (every key required).
#pragma once

#include "dlslot/config.hpp"
#include "trajectory_associator.hpp"

namespace dlslot::tracker {

// Which tracks the results files and SLOT_STATE consumers report.
enum class TrackOutput {
  Confirmed,  // confirmed tracks only (the default: what a user reads as the system's answer)
  All,        // every association, tentative ones too, each with its confidence (for sAMOTA sweeps)
};
TrackOutput trackOutputFromName(const std::string& name);  // "confirmed" | "all"

struct TrackerConfig {
  AssociatorConfig associator;
  TrackOutput output = TrackOutput::Confirmed;
  double join_timeout_s = 2.0;

  // Throws ConfigError naming the file and the key.
  static TrackerConfig read(ConfigSection section);
};

}  // namespace dlslot::tracker
