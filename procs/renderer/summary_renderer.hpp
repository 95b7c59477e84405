// One image for a whole run: the three ego trajectories over an accumulated map of kept points,
// every track's path (dynamic: line with its heading at the end; static: its box), and the
// numbers a reader checks first (path lengths, end-point and RMS error against ground truth).
#pragma once

#include <opencv2/core.hpp>

#include "density_map.hpp"
#include "render_config.hpp"
#include "run_state.hpp"

namespace dlslot::renderer {

// `map` may be null or empty (no map layer).
cv::Mat renderSummary(const RunSummary& run, const DensityMap* map, const SummaryConfig& cfg);

}  // namespace dlslot::renderer
