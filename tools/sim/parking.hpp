// Parked vehicles along the roads' parking strips (parallel or in stalls), clear of lanes,
// junctions, routes, structures and each other. They stand still the whole sequence.
#pragma once

#include <vector>

#include "traffic.hpp"

namespace dlslot::sim {

std::vector<Agent> parkVehicles(const Scenario& scenario, const World& world);

}  // namespace dlslot::sim
