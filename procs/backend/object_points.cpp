#include "backend/object_points.hpp"

#include <algorithm>
#include <cmath>

#include "backend/line_of_sight.hpp"
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
    const double sigma = config.boxLengthwiseSigma(o.box.center.norm());
    const double margin = std::max(config.registration_box_margin, config.registration_box_margin_sigmas * sigma);
    const Box v = removalVolume(o.box, margin, config.registration_ground_clearance);
    if (v.size.z() <= 0.0) continue;
    volumes.push_back(v);
    owner.push_back(static_cast<int>(i));
  }
  if (volumes.empty()) return;
  const std::vector<std::vector<int>> members = pointsOfBoxes(scan, volumes, 0.0);
  std::vector<const ObjectPoints*> objects;
  for (size_t b = 0; b < volumes.size(); ++b) {
    auto points = std::make_shared<ObjectPoints>();
    points->reserve(members[b].size());
    for (int i : members[b]) points->push_back(scan.col(i).head<3>());
    objects.push_back(points.get());
    observations[owner[b]].points = std::move(points);
  }
  // Which ends a side saw matters only where it is shorter than the vehicle (endsThatCount): here,
  // than its box, shown by enough points not facing the sensor. A scan left out keeps both ends
  // "seen", which a short side contradicts: it counts neither, as without the test.
  if (config.side_azimuth_step_deg <= 0) return;
  std::vector<size_t> short_sides;
  std::vector<const ObjectPoints*> tested;
  for (size_t b = 0; b < volumes.size(); ++b) {
    const Box& box = observations[owner[b]].box;
    const std::optional<SideEnds> ends =
        sideEnds(*objects[b], Eigen::Vector3d(std::cos(box.yaw), std::sin(box.yaw), 0.0));
    if (static_cast<int>(objects[b]->size()) < config.line_of_sight_min_points ||
        facesTheSensor(box, config.line_of_sight_max_angle_deg) || !ends ||
        ends->length() >= box.size.x() - config.side_length_tolerance)
      continue;
    short_sides.push_back(b);
    tested.push_back(objects[b]);
  }
  if (short_sides.empty()) return;
  const AzimuthIndex index(scan, config.side_azimuth_step_deg * M_PI / 180.0, tested);
  for (size_t b : short_sides) observations[owner[b]].ends_seen = endsSeen(index, *objects[b], volumes[b]);
}

}  // namespace dlslot::backend
