#include "backend/object_points.hpp"

#include <algorithm>

#include "dlslot/box_filter.hpp"

namespace dlslot::backend {

void attachObjectPoints(const PointCloud& scan, const BackendConfig& config, std::vector<ObservationInput>& observations) {
  std::vector<Box> volumes;
  std::vector<int> owner;
  for (size_t i = 0; i < observations.size(); ++i) {
    const ObservationInput& o = observations[i];
    if (std::find(config.registration_types.begin(), config.registration_types.end(), o.box.type) ==
        config.registration_types.end())
      continue;
    const double sigma = config.observation_sigma[0] * config.observationNoiseGrowth(o.box.center.norm());
    const double margin = std::max(config.registration_box_margin, config.registration_box_margin_sigmas * sigma);
    const Box v = removalVolume(o.box, margin, config.registration_ground_clearance);
    if (v.size.z() <= 0.0) continue;
    volumes.push_back(v);
    owner.push_back(static_cast<int>(i));
  }
  if (volumes.empty()) return;
  const std::vector<std::vector<int>> members = pointsOfBoxes(scan, volumes, 0.0);
  for (size_t b = 0; b < volumes.size(); ++b) {
    auto points = std::make_shared<ObjectPoints>();
    points->reserve(members[b].size());
    for (int i : members[b]) points->push_back(scan.col(i).head<3>());
    observations[owner[b]].points = std::move(points);
  }
}

}  // namespace dlslot::backend
