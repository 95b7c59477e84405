// The report's plots, drawn with OpenCV (headless PNG).
#pragma once

#include <map>
#include <optional>
#include <string>

#include "trajectory.hpp"
#include "velocity_breakdown.hpp"

namespace dlslot::eval {

// Bird's-eye view (x, y of the world = first scan's lidar frame, equal scales) of every source
// over the ground truth, as estimated (not aligned).
void plotTrajectories(const std::string& path, const std::map<std::string, Trajectory>& sources,
                      const std::optional<Trajectory>& truth);

// Position error after Umeyama alignment of every source against the distance travelled along
// the ground truth.
void plotErrorOverDistance(const std::string& path, const std::map<std::string, Trajectory>& sources,
                           const Trajectory& truth);

// The velocity error of dynamic objects against their range, young tracks (< 5 scans) and older
// ones apart, each beside the RMS error its tracks' own covariances predict (dashed).
void plotVelocityErrorByRange(const std::string& path, const std::vector<VelocityBin>& young,
                              const std::vector<VelocityBin>& older);

// The same against the track's age (velocityErrorByAge's bins, last_age holding the older tracks):
// how soon a new track's velocity can be trusted.
void plotVelocityErrorByAge(const std::string& path, const std::vector<VelocityBin>& bins, int last_age);

}  // namespace dlslot::eval
