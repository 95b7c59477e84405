// Each observed object's points in a scan, for the per-object registration: the points inside its
// box grown by a margin (wider far away, where the box is less certain: BackendConfig), above the
// ground (the box's floor raised by a clearance: the volume A-LOAM* removes, dlslot/box_filter.hpp).
#pragma once

#include <vector>

#include "backend/backend_config.hpp"
#include "backend/backend_types.hpp"
#include "dlslot/types.hpp"

namespace dlslot::backend {

// Sets `points` of every observation whose class the config registers (lidar frame), and, for a
// side shorter than its box, which of its ends the scan saw (side_ends.hpp: endsSeen).
void attachObjectPoints(const PointCloud& scan, const BackendConfig& config, std::vector<ObservationInput>& observations);

}  // namespace dlslot::backend
