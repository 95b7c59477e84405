// Message <-> backend type conversion for the node (the core never sees LCM types).
#pragma once

#include <string>

#include "backend/backend_types.hpp"
#include "dlslot/associations_t.hpp"
#include "dlslot/odometry_t.hpp"
#include "dlslot/slot_state_t.hpp"

namespace dlslot::backend {

OdometryInput fromMsg(const odometry_t& m);
// The observations of an ASSOCIATIONS message; boxes with NaN or non-positive sizes are
// skipped and counted in `rejected`.
std::vector<ObservationInput> observationsFromMsg(const associations_t& m, int* rejected);
slot_state_t toMsg(const BackendOutput& out, const std::string& mode);

}  // namespace dlslot::backend
