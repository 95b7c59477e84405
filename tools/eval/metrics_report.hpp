// The evaluation's outputs: metrics.json (flat object, one dotted key per number, null where a
// metric cannot be measured), report.md (tables) and the summary printed to stdout.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "evaluation.hpp"

namespace dlslot::eval {

// Keys: ego.source, ego.<k> for the primary source and sources.<name>.<k> for every source, with
// k in ate_rmse_m rpe1_t_m rpe1_r_deg rpe10_t_m rpe10_r_deg t_rel_pct r_rel_deg_per_100m
// t_rel_short_pct r_rel_short_deg_per_100m; tracking.<k> (centre distance) and tracking_iou.<k>
// (3D IoU) with k in mota motp_m idsw fp fn hota velocity_rmse_mps; timing_ms.<module>.mean and
// .p95; frames.<channel>.
std::string metricsJson(const Metrics& m);
void writeMetricsJson(const std::string& path, const Metrics& m);

// report.md: tables of every metric, notes, and the plots (paths relative to the report).
std::string reportMarkdown(const Metrics& m, const std::vector<std::string>& plots);
void writeReport(const std::string& path, const Metrics& m, const std::vector<std::string>& plots);

// One line: the primary source's ATE and t_rel, MOTA, HOTA, IDSW.
std::string summaryLine(const Metrics& m);
// The summary line and a table of the headline numbers.
void printSummary(std::ostream& out, const Metrics& m);

}  // namespace dlslot::eval
