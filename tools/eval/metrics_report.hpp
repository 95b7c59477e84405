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
// (3D IoU) with k in mota motp_m idsw fp fn hota velocity_rmse_mps; the KITTI protocol's
// tracking.<class>.<k> (class car, pedestrian, cyclist; kitti_protocol.hpp) with k in mota motp
// samota amota idsw frag tp fp fn labels ignored_labels ignored_tracks hota deta assa
// recall_points best_mota best_idsw best_threshold samota_ab3dmot amota_ab3dmot best_mota_ab3dmot; timing_ms.<module>.mean and
// .p95; frames.<channel>.
std::string metricsJson(const Metrics& m);
// The KITTI protocol's numbers of one class as (key, value) pairs, in metrics.json's order.
std::vector<std::pair<std::string, std::optional<double>>> kittiValues(const KittiClassMetrics& k);
void writeMetricsJson(const std::string& path, const Metrics& m);
// One row per matched pair with a velocity on both sides (VelocityPair), for plots of your own.
void writeVelocityErrorsCsv(const std::string& path, const Metrics& m);

// report.md: tables of every metric, notes, and the plots (paths relative to the report).
std::string reportMarkdown(const Metrics& m, const std::vector<std::string>& plots);
void writeReport(const std::string& path, const Metrics& m, const std::vector<std::string>& plots);

// One line: the primary source's ATE and t_rel, MOTA, HOTA, IDSW.
std::string summaryLine(const Metrics& m);
// The summary line and a table of the headline numbers.
void printSummary(std::ostream& out, const Metrics& m);

}  // namespace dlslot::eval
