// Which points of a scan fall inside detected boxes: the A-LOAM* filter (paper III-D) and the
// renderer's "removed as dynamic" layer use this one function.
#pragma once

#include <vector>

#include "dlslot/types.hpp"

namespace dlslot {

// mask[i] is true when point i lies inside any box grown by `margin` metres on every side.
std::vector<bool> pointsInBoxes(const PointCloud& scan, const std::vector<Box>& boxes, double margin);

// The points whose mask entry is false.
PointCloud keepOutside(const PointCloud& scan, const std::vector<bool>& inside);

}  // namespace dlslot
