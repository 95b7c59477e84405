// The report's plots, drawn with OpenCV (headless PNG).
#pragma once

#include <map>
#include <optional>
#include <string>

#include "trajectory.hpp"

namespace dlslot::eval {

// Bird's-eye view (x, y of the world = first scan's lidar frame, equal scales) of every source
// over the ground truth, as estimated (not aligned).
void plotTrajectories(const std::string& path, const std::map<std::string, Trajectory>& sources,
                      const std::optional<Trajectory>& truth);

// Position error after Umeyama alignment of every source against the distance travelled along
// the ground truth.
void plotErrorOverDistance(const std::string& path, const std::map<std::string, Trajectory>& sources,
                           const Trajectory& truth);

}  // namespace dlslot::eval
