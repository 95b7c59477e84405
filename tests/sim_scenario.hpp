// A scenario shipped in config/scenarios/, cut to a number of frames (for the simulator's tests).
#pragma once

#include <string>

#include "sim/scenario.hpp"

namespace dlslot::sim::test {

inline Scenario shippedScenario(const std::string& name, int frames) {
  Scenario sc = loadScenario(std::string(DLSLOT_SOURCE_DIR) + "/config/scenarios/" + name + ".yaml");
  sc.frames = frames;
  return sc;
}

}  // namespace dlslot::sim::test
