#include "metrics_report.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <sstream>

#include "dlslot/input_error.hpp"

namespace dlslot::eval {
namespace {

using Opt = std::optional<double>;

std::string num(Opt v, const char* fmt = "%.9g") {
  if (!v || !std::isfinite(*v)) return "null";
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, *v);
  return buf;
}

std::string cell(Opt v, const char* fmt) { return v && std::isfinite(*v) ? num(v, fmt) : "-"; }

std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    if (static_cast<unsigned char>(c) < 0x20) continue;
    out += c;
  }
  return out + "\"";
}

// The ego keys, in the order the issue lists them, with their value in EgoMetrics.
const std::vector<std::pair<std::string, std::function<Opt(const EgoMetrics&)>>>& egoKeys() {
  static const std::vector<std::pair<std::string, std::function<Opt(const EgoMetrics&)>>> keys = {
      {"ate_rmse_m", [](const EgoMetrics& e) { return e.ate_rmse_m; }},
      {"rpe1_t_m", [](const EgoMetrics& e) { return e.rpe1_t_m; }},
      {"rpe1_r_deg", [](const EgoMetrics& e) { return e.rpe1_r_deg; }},
      {"rpe10_t_m", [](const EgoMetrics& e) { return e.rpe10_t_m; }},
      {"rpe10_r_deg", [](const EgoMetrics& e) { return e.rpe10_r_deg; }},
      {"t_rel_pct", [](const EgoMetrics& e) { return e.t_rel_pct; }},
      {"r_rel_deg_per_100m", [](const EgoMetrics& e) { return e.r_rel_deg_per_100m; }},
      {"t_rel_short_pct", [](const EgoMetrics& e) { return e.t_rel_short_pct; }},
      {"r_rel_short_deg_per_100m", [](const EgoMetrics& e) { return e.r_rel_short_deg_per_100m; }},
      {"velocity_rmse_mps", [](const EgoMetrics& e) { return e.velocity_rmse_mps; }},
      {"implausible_frames", [](const EgoMetrics& e) { return e.implausible_frames; }},
  };
  return keys;
}

std::vector<std::pair<std::string, Opt>> trackingValues(const std::optional<TrackingMetrics>& t) {
  const auto count = [&](int ClearMot::*field) -> Opt {
    return t ? Opt(static_cast<double>(t->clear.*field)) : std::nullopt;
  };
  // Tracks younger than 5 scans: the velocity breakdown's first age bin.
  Opt young;
  if (t)
    for (const VelocityGroup& g : t->velocity_groups)
      if (g.dimension == "age" && g.bin == "0-4") young = g.rmse_mps;
  const VelocityCalibration all = t ? velocityCalibration(t->clear.velocities, 0, INT_MAX) : VelocityCalibration{};
  const VelocityCalibration young_calibration = t ? velocityCalibration(t->clear.velocities, 0, 4) : VelocityCalibration{};
  return {{"mota", t ? t->clear.mota : std::nullopt},
          {"motp_m", t ? t->clear.motp_m : std::nullopt},
          {"idsw", count(&ClearMot::idsw)},
          {"fp", count(&ClearMot::fp)},
          {"fn", count(&ClearMot::fn)},
          {"hota", t && t->hota ? Opt(t->hota->hota) : std::nullopt},
          {"velocity_rmse_mps", t ? t->clear.velocity_rmse_mps : std::nullopt},
          {"velocity_young_rmse_mps", young},
          {"velocity_nees", all.nees_mean},
          {"velocity_within_95", all.within_95},
          {"velocity_young_within_95", young_calibration.within_95},
          {"heading_rmse_deg", t ? t->clear.heading_rmse_deg : std::nullopt},
          {"heading_pairs", count(&ClearMot::heading_pairs)},
          {"heading_reversed", count(&ClearMot::heading_reversed)},
          {"heading_rmse_unreversed_deg", t ? t->clear.heading_rmse_unreversed_deg : std::nullopt}};
}


// A table rendered as Markdown with padded columns, so it reads well in a terminal too.
class Table {
 public:
  explicit Table(std::vector<std::string> header) : rows_{std::move(header)} {}
  void row(std::vector<std::string> cells) { rows_.push_back(std::move(cells)); }
  bool empty() const { return rows_.size() == 1; }
  std::string render() const {
    std::vector<size_t> width(rows_[0].size(), 3);
    for (const auto& r : rows_)
      for (size_t c = 0; c < r.size(); ++c) width[c] = std::max(width[c], r[c].size());
    std::ostringstream out;
    for (size_t i = 0; i < rows_.size(); ++i) {
      out << "|";
      for (size_t c = 0; c < width.size(); ++c) {
        const std::string& s = c < rows_[i].size() ? rows_[i][c] : std::string();
        out << " " << s << std::string(width[c] - s.size(), ' ') << " |";
      }
      out << "\n";
      if (i == 0) {
        out << "|";
        for (size_t w : width) out << std::string(w + 2, '-') << "|";
        out << "\n";
      }
    }
    return out.str();
  }

 private:
  std::vector<std::vector<std::string>> rows_;
};

Table egoTable(const Metrics& m) {
  Table t({"source", "frames", "path m", "ATE m", "ATE unaligned m", "RPE1 t m", "RPE1 r deg", "RPE10 t m",
           "RPE10 r deg", "t_rel %", "r_rel deg/100m", "t_rel 10-80m %", "r_rel 10-80m deg/100m",
           "velocity err m/s"});
  for (const auto& [name, e] : m.ego) {
    const std::string label = name + (name == m.primary_source ? " (primary)" : "");
    if (!e) {
      t.row({label, "-", "-", "no ground truth"});
      continue;
    }
    t.row({label, std::to_string(e->frames), cell(e->path_length_m, "%.1f"), cell(e->ate_rmse_m, "%.3f"),
           cell(e->ate_unaligned_rmse_m, "%.3f"), cell(e->rpe1_t_m, "%.4f"), cell(e->rpe1_r_deg, "%.4f"),
           cell(e->rpe10_t_m, "%.3f"), cell(e->rpe10_r_deg, "%.3f"), cell(e->t_rel_pct, "%.3f"),
           cell(e->r_rel_deg_per_100m, "%.4f"), cell(e->t_rel_short_pct, "%.3f"),
           cell(e->r_rel_short_deg_per_100m, "%.4f"), cell(e->velocity_rmse_mps, "%.3f")});
  }
  return t;
}

Table trackingTable(const Metrics& m) {
  Table t({"matching", "MOTA", "MOTP m", "IDSW", "FP", "FN", "TP", "labels", "HOTA", "DetA", "AssA", "LocA",
           "velocity RMSE m/s", "velocity pairs", "heading RMSE deg (moving cars)"});
  for (const auto* tm : {&m.tracking, &m.tracking_iou}) {
    if (!*tm) continue;
    const ClearMot& c = (*tm)->clear;
    const std::optional<Hota>& h = (*tm)->hota;
    t.row({(*tm)->criterion.describe(), cell(c.mota, "%.4f"), cell(c.motp_m, "%.3f"), std::to_string(c.idsw),
           std::to_string(c.fp), std::to_string(c.fn), std::to_string(c.tp), std::to_string(c.num_truth),
           cell(h ? Opt(h->hota) : std::nullopt, "%.4f"), cell(h ? Opt(h->deta) : std::nullopt, "%.4f"),
           cell(h ? Opt(h->assa) : std::nullopt, "%.4f"), cell(h ? Opt(h->loca) : std::nullopt, "%.4f"),
           cell(c.velocity_rmse_mps, "%.3f"), std::to_string(c.velocity_pairs), cell(c.heading_rmse_deg, "%.2f")});
  }
  return t;
}

Table classTable(const Metrics& m) {
  Table t({"class", "MOTA", "IDSW", "FP", "FN", "TP", "labels", "velocity RMSE m/s"});
  for (const auto& [cls, c] : m.tracking_by_class)
    t.row({cls, cell(c.mota, "%.4f"), std::to_string(c.idsw), std::to_string(c.fp), std::to_string(c.fn),
           std::to_string(c.tp), std::to_string(c.num_truth), cell(c.velocity_rmse_mps, "%.3f")});
  return t;
}

// Where the KITTI protocol scores a small share of a class's labels, says so beside its line: the
// camera sees ahead only, and its rules leave out labels cut by the image's edge or hidden, so a
// scene whose people walk beside the ego leaves the protocol a few far, briefly seen ones.
std::string kittiCoverageNotes(const Metrics& m) {
  std::string notes;
  for (const auto& [cls, k] : m.kitti) {
    const int all = k.all.labels + k.all.ignored_labels;
    if (all == 0 || k.all.labels * 2 >= all) continue;
    char buf[320];
    std::snprintf(buf, sizeof buf,
                  "Note: the KITTI protocol scores %d of the %d %s labels (the others lie outside the camera's image, "
                  "are cut by its edge, hidden, or of the neighbour class); the all-around table scores every one.\n",
                  k.all.labels, all, cls.c_str());
    notes += buf;
  }
  return notes;
}

Table kittiTable(const Metrics& m) {
  Table t({"class", "sAMOTA", "AMOTA", "MOTA", "MOTP", "IDSW", "FRAG", "TP", "FP", "FN", "labels", "ignored labels",
           "ignored tracks", "HOTA", "best MOTA", "at score", "AB3DMOT script: sAMOTA", "AMOTA", "best MOTA"});
  for (const auto& [cls, k] : m.kitti)
    t.row({cls, cell(k.sweep.samota, "%.4f"), cell(k.sweep.amota, "%.4f"), cell(k.all.mota, "%.4f"),
           cell(k.all.motp, "%.4f"), std::to_string(k.all.idsw), std::to_string(k.all.frag), std::to_string(k.all.tp),
           std::to_string(k.all.fp), std::to_string(k.all.fn), std::to_string(k.all.labels),
           std::to_string(k.all.ignored_labels), std::to_string(k.all.ignored_tracks),
           cell(k.hota ? Opt(k.hota->hota) : std::nullopt, "%.4f"), cell(k.sweep.best.mota, "%.4f"),
           k.sweep.best_threshold ? cell(k.sweep.best_threshold, "%.4g") : "all", cell(k.sweep_ab3dmot.samota, "%.4f"),
           cell(k.sweep_ab3dmot.amota, "%.4f"), cell(k.sweep_ab3dmot.best.mota, "%.4f")});
  return t;
}

Table velocityTable(const TrackingMetrics& t) {
  Table table({"by", "group", "pairs", "RMSE m/s", "mean m/s", "p90 m/s"});
  for (const VelocityGroup& g : t.velocity_groups)
    table.row({g.dimension, g.bin, std::to_string(g.pairs), cell(g.rmse_mps, "%.3f"), cell(g.mean_mps, "%.3f"),
               cell(g.p90_mps, "%.3f")});
  return table;
}

Table timingTable(const Metrics& m) {
  Table t({"module", "frames", "mean ms", "p95 ms", "max ms"});
  for (const auto& [module, s] : m.timing_ms)
    t.row({module, std::to_string(s.count()), cell(s.mean(), "%.2f"), cell(s.percentile(95), "%.2f"),
           cell(s.max(), "%.2f")});
  return t;
}

void writeText(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  if (!out) throw InputError(path, 0, "cannot open for writing");
  out << text;
  if (!out) throw InputError(path, 0, "write failed");
}

}  // namespace

// The KITTI protocol's keys of one class, tracking.<class>.<key>.
std::vector<std::pair<std::string, std::optional<double>>> kittiValues(const KittiClassMetrics& k) {
  const auto count = [](int v) -> std::optional<double> { return std::optional<double>(static_cast<double>(v)); };
  return {{"mota", k.all.mota},
          {"motp", k.all.motp},
          {"samota", k.sweep.samota},
          {"amota", k.sweep.amota},
          {"idsw", count(k.all.idsw)},
          {"frag", count(k.all.frag)},
          {"tp", count(k.all.tp)},
          {"fp", count(k.all.fp)},
          {"fn", count(k.all.fn)},
          {"labels", count(k.all.labels)},
          {"ignored_labels", count(k.all.ignored_labels)},
          {"ignored_tracks", count(k.all.ignored_tracks)},
          {"hota", k.hota ? std::optional<double>(k.hota->hota) : std::nullopt},
          {"deta", k.hota ? std::optional<double>(k.hota->deta) : std::nullopt},
          {"assa", k.hota ? std::optional<double>(k.hota->assa) : std::nullopt},
          {"recall_points", count(k.sweep.recall_points_reached)},
          {"best_mota", k.sweep.best.mota},
          {"best_idsw", count(k.sweep.best.idsw)},
          {"best_threshold", k.sweep.best_threshold},
          {"samota_ab3dmot", k.sweep_ab3dmot.samota},
          {"amota_ab3dmot", k.sweep_ab3dmot.amota},
          {"best_mota_ab3dmot", k.sweep_ab3dmot.best.mota}};
}

std::string metricsJson(const Metrics& m) {
  std::vector<std::pair<std::string, std::string>> kv;
  const auto ego_entries = [&](const std::string& prefix, const std::optional<EgoMetrics>& e) {
    for (const auto& [key, get] : egoKeys()) kv.emplace_back(prefix + key, num(e ? get(*e) : std::nullopt));
  };
  const auto primary = m.ego.find(m.primary_source);
  kv.emplace_back("ego.source", m.primary_source.empty() ? "null" : quoted(m.primary_source));
  ego_entries("ego.", primary != m.ego.end() ? primary->second : std::nullopt);
  // The backend's test of the odometry factor (null without SLOT_STATE).
  const auto& oc = m.odometry_checks;
  kv.emplace_back("ego.odometry_tested_frames", num(oc ? Opt(oc->tested) : std::nullopt));
  kv.emplace_back("ego.odometry_disagreement_frames", num(oc ? Opt(oc->disagreed) : std::nullopt));
  kv.emplace_back("ego.odometry_downweighted_frames", num(oc ? Opt(oc->downweighted) : std::nullopt));
  kv.emplace_back("ego.odometry_max_disagreement_m", num(oc ? Opt(oc->max_disagreement_m) : std::nullopt));
  for (const auto& [name, e] : m.ego) ego_entries("sources." + name + ".", e);
  for (const auto& [key, v] : trackingValues(m.tracking)) kv.emplace_back("tracking." + key, num(v));
  kv.emplace_back("tracking.label_velocity_half_span_s", num(m.tracking ? Opt(m.label_velocity_half_span_s) : std::nullopt));
  for (const auto& [key, v] : trackingValues(m.tracking_iou)) kv.emplace_back("tracking_iou." + key, num(v));
  for (const auto& [cls, c] : m.tracking_by_class) {
    const std::string k = "tracking_all_around." + cls + ".";
    kv.emplace_back(k + "mota", num(c.mota));
    kv.emplace_back(k + "idsw", num(c.idsw));
    kv.emplace_back(k + "fp", num(c.fp));
    kv.emplace_back(k + "fn", num(c.fn));
    kv.emplace_back(k + "labels", num(c.num_truth));
    kv.emplace_back(k + "velocity_rmse_mps", num(c.velocity_rmse_mps));
  }
  for (const auto& [cls, k] : m.kitti)
    for (const auto& [key, v] : kittiValues(k)) kv.emplace_back("tracking." + cls + "." + key, num(v));
  if (m.tracking)
    for (const VelocityGroup& g : m.tracking->velocity_groups) {
      const std::string prefix = "velocity." + g.dimension + "." + g.bin + ".";
      kv.emplace_back(prefix + "pairs", std::to_string(g.pairs));
      kv.emplace_back(prefix + "rmse_mps", num(g.rmse_mps));
      kv.emplace_back(prefix + "p90_mps", num(g.p90_mps));
    }
  for (const auto& [module, s] : m.timing_ms) {
    kv.emplace_back("timing_ms." + module + ".mean", num(s.count() ? Opt(s.mean()) : std::nullopt));
    kv.emplace_back("timing_ms." + module + ".p95", num(s.count() ? Opt(s.percentile(95)) : std::nullopt));
  }
  for (const auto& [channel, n] : m.frame_counts) kv.emplace_back("frames." + channel, std::to_string(n));
  if (m.frames) {
    const FrameAccounting& f = *m.frames;
    kv.emplace_back("frames.played", std::to_string(f.played));
    for (const ProcessFrames& p : f.processes) {
      kv.emplace_back("frames.received." + p.name, std::to_string(p.received));
      kv.emplace_back("frames.handled." + p.name, std::to_string(p.handled));
      kv.emplace_back("frames.skipped." + p.name, std::to_string(p.skipped));
      kv.emplace_back("frames.lost." + p.name, std::to_string(p.lost));
    }
    kv.emplace_back("frames.lost", std::to_string(f.lost()));
    kv.emplace_back("frames.without_odometry", std::to_string(f.without_odometry));
    kv.emplace_back("frames.without_associations", std::to_string(f.without_associations));
    kv.emplace_back("frames.without_detections", std::to_string(f.without_detections));
    kv.emplace_back("frames.kernel_udp_drops", std::to_string(f.kernel_drops));
  }
  for (const auto& [process, r] : m.memory) {
    kv.emplace_back("memory.rss_mb." + process + ".start", num(r.start_mb));
    kv.emplace_back("memory.rss_mb." + process + ".middle", num(r.middle_mb));
    kv.emplace_back("memory.rss_mb." + process + ".three_quarters", num(r.three_quarters_mb));
    kv.emplace_back("memory.rss_mb." + process + ".end", num(r.end_mb));
  }
  for (const auto& [outcome, n] : m.registration) kv.emplace_back("registration." + outcome, std::to_string(n));
  if (m.map) {
    const MapScore& s = m.map->score;
    kv.emplace_back("map.sa", num(s.sa));
    kv.emplace_back("map.da", num(s.da));
    kv.emplace_back("map.aa", num(s.aa));
    kv.emplace_back("map.voxel_m", num(s.voxel_m));
    kv.emplace_back("map.static_voxels", std::to_string(s.static_voxels));
    kv.emplace_back("map.dynamic_voxels", std::to_string(s.dynamic_voxels));
    kv.emplace_back("map.keyframes", std::to_string(m.map->keyframes));
    kv.emplace_back("map.points", std::to_string(m.map->map_points));
    kv.emplace_back("map.loops_accepted", std::to_string(m.map->loops_accepted));
    kv.emplace_back("map.loops_false", m.map->loops_false ? std::to_string(*m.map->loops_false) : "null");
    kv.emplace_back("map.end_to_start_m", num(m.map->end_to_start_m));
    kv.emplace_back("map.slot_end_to_start_m", num(m.map->slot_end_to_start_m));
  }
  std::string out = "{\n";
  for (size_t i = 0; i < kv.size(); ++i)
    out += "  " + quoted(kv[i].first) + ": " + kv[i].second + (i + 1 < kv.size() ? ",\n" : "\n");
  return out + "}\n";
}

void writeMetricsJson(const std::string& path, const Metrics& m) { writeText(path, metricsJson(m)); }

std::string reportMarkdown(const Metrics& m, const std::vector<std::string>& plots) {
  std::ostringstream out;
  out << "# DL-SLOT evaluation\n\n" << summaryLine(m) << "\n\n";
  out << "## Ego motion\n\n";
  if (m.ego.empty()) {
    out << "No ego trajectory in the input.\n\n";
  } else {
    out << egoTable(m).render() << "\n"
        << "ATE: RMSE of the position after SE(3) Umeyama alignment (unaligned: in the world of the first "
           "scan, the ground truth anchored at the run's first frame when the run started later). RPE: RMSE over frame pairs 1 and 10 scans apart. Velocity err: the RMSE of the ego's velocity over 5 scans (the span of the backend's object velocities, whose error over ground includes it). t_rel / r_rel: KITTI devkit segments "
           "of 100..800 m starting every 10 frames (and 10..80 m), poses in the lidar frame.\n\n";
  }
  if (const auto& oc = m.odometry_checks) {
    out << "The backend tested the odometry against the motion of its landmarks and tracked objects on " << oc->tested
        << " frames: they disagreed beyond both covariances on " << oc->disagreed << " (odometry down-weighted on "
        << oc->downweighted << ")";
    if (oc->disagreed > 0) {
      out << ", by up to " << cell(oc->max_disagreement_m, "%.3f") << " m; frames";
      for (size_t i = 0; i < oc->disagreed_frames.size() && i < 50; ++i) out << " " << oc->disagreed_frames[i];
      if (oc->disagreed_frames.size() > 50) out << " ...";
    }
    out << ".\n\n";
  }
  out << "## Tracking (bird's-eye view, each scan's lidar frame)\n\n";
  if (!m.tracking) {
    out << "Not measurable: the input has no labels or no tracks.\n\n";
  } else {
    out << trackingTable(m).render() << "\n";
    if (!m.tracking_by_class.empty())
      out << "Per class, every label all around the sensor (" << m.tracking->criterion.describe() << "):\n\n"
          << classTable(m).render() << "\n";
    out << "Tracks (world frame) are moved into each scan's lidar frame with the system's own ego pose. Classes "
           "match as in the KITTI devkit (Car~Van, Pedestrian~Person_sitting); tracks in DontCare regions count "
           "neither as false nor as true positives. HOTA: mean over alpha = 0.05..0.95; similarity = 3D IoU for "
           "the IoU line, max(0, 1 - d / "
        << num(m.tracking->criterion.max_distance_m, "%g") << " m) of the centre distance d for the distance line.\n\n"
        << "Velocities: " << m.velocity_frame << ".\n\n";
    if (!m.tracking->velocity_groups.empty())
      out << "### Velocity error by track age (scans since first output), class, motion, range (m, the "
             "label's from the sensor) and stretch of the sequence\n\n"
          << velocityTable(*m.tracking).render()
          << "\nAge, class, range and stretch rows: dynamic labels only, as the velocity RMSE; motion rows: "
             "both.\n\n";
    const VelocityCalibration all = velocityCalibration(m.tracking->clear.velocities, 0, INT_MAX);
    const VelocityCalibration young = velocityCalibration(m.tracking->clear.velocities, 0, 4);
    if (all.pairs > 0)
      out << "Velocity covariances: " << num(100 * *all.within_95, "%.1f") << " % of " << all.pairs
          << " velocity errors of moving objects lie inside their track's 95 % ellipse (tracks younger than 5 "
          << "scans: " << num(young.within_95 ? Opt(100 * *young.within_95) : std::nullopt, "%.1f") << " % of "
          << young.pairs << "; 95 % if honest, less if overconfident); mean NEES " << num(all.nees_mean, "%.2f")
          << " (2 if honest).\n\n";
  }
  if (!m.kitti.empty()) {
    out << "## Tracking, KITTI protocol (3-D IoU >= " << num(m.kitti.begin()->second.min_iou, "%g")
        << ", the devkit's ignore rules)\n\n"
        << kittiTable(m).render() << "\n" << kittiCoverageNotes(m) << "\n"
        << "As the KITTI devkit and AB3DMOT's scripts/KITTI/evaluate.py count: camera frame, tracks outside the "
           "image not scored; labels truncated (> 0), occluded (> 2) or of the neighbour class (Van, "
           "Person_sitting) ignored; unmatched tracks of the neighbour class, at most 25 px tall or more than half "
           "in a DontCare box ignored. MOTA, MOTP (mean 3-D IoU), IDSW, FRAG, TP (every match, ignored labels' "
           "included), FP, FN: all tracks. sAMOTA / AMOTA: over 40 recall points from the tracks' mean scores. "
           "Best MOTA: at the recall point's score threshold with the highest MOTA (AB3DMOT's single-threshold "
           "line). AB3DMOT script: the same sweep with the script's drifting mean scores (its numbers to the digit; "
           "it drops a track whose mean is itself the threshold at some recall points). HOTA: 3-D IoU similarity "
           "after the ignore rules.\n\n";
  }
  out << "## Timing (per frame)\n\n";
  if (m.timing_ms.empty())
    out << "No timings in the input.\n\n";
  else
    out << timingTable(m).render() << "\n";
  if (!m.frame_counts.empty()) {
    out << "## Messages in the log\n\n";
    Table t({"channel", "messages"});
    for (const auto& [channel, n] : m.frame_counts) t.row({channel, std::to_string(n)});
    out << t.render() << "\n";
  }
  if (m.frames) {
    const FrameAccounting& f = *m.frames;
    out << "## Frames per process\n\n" << f.played << " frames played.\n\n";
    Table t({"process", "received", "handled", "skipped", "lost"});
    for (const ProcessFrames& p : f.processes)
      t.row({p.name, std::to_string(p.received), std::to_string(p.handled), std::to_string(p.skipped),
             std::to_string(p.lost)});
    out << t.render() << "\nSolved without odometry: " << f.without_odometry << "; without associations: "
        << f.without_associations << "; without detections: " << f.without_detections
        << "; UDP datagrams dropped by the kernel: " << f.kernel_drops << ".\n\n**" << f.verdict() << "**\n\n";
  }
  if (!m.memory.empty()) {
    out << "## Memory (resident, MB)\n\n";
    Table t({"process", "start", "middle", "3/4", "end"});
    char buf[32];
    auto mb = [&](double v) { std::snprintf(buf, sizeof buf, "%.1f", v); return std::string(buf); };
    for (const auto& [process, r] : m.memory) t.row({process, mb(r.start_mb), mb(r.middle_mb), mb(r.three_quarters_mb), mb(r.end_mb)});
    out << t.render() << "\n";
  }
  if (m.map) {
    const MapScore& s = m.map->score;
    out << "## Static map (dlslot-mapper; dynamic-map benchmark terms on a " << s.voxel_m << " m voxel grid, the grid the map counted its points on)\n\n";
    Table t({"AA", "SA", "DA", "static voxels", "dynamic voxels", "keyframes", "map points", "loops accepted",
             "false loops"});
    t.row({cell(s.aa, "%.4f"), cell(s.sa, "%.4f"), cell(s.da, "%.4f"), std::to_string(s.static_voxels),
           std::to_string(s.dynamic_voxels), std::to_string(m.map->keyframes), std::to_string(m.map->map_points),
           std::to_string(m.map->loops_accepted), m.map->loops_false ? std::to_string(*m.map->loops_false) : "-"});
    out << t.render() << "\n";
  }
  if (!m.notes.empty()) {
    out << "## Notes\n\n";
    for (const std::string& n : m.notes) out << "- " << n << "\n";
    out << "\n";
  }
  if (!plots.empty()) {
    out << "## Plots\n\n";
    for (const std::string& p : plots) out << "![" << p << "](" << p << ")\n\n";
  }
  return out.str();
}

void writeVelocityErrorsCsv(const std::string& path, const Metrics& m) {
  std::ostringstream out;
  // The track's covariance and NEES empty where it gave none.
  out << "frame_index,label_id,track_id,class,dynamic,track_age,truth_vx,truth_vy,track_vx,track_vy,error_mps,"
         "track_cov_xx,track_cov_xy,track_cov_yy,nees,range_m\n";
  if (m.tracking)
    for (const VelocityPair& p : m.tracking->clear.velocities) {
      char buf[256];
      std::snprintf(buf, sizeof buf, "%d,%d,%d,%s,%d,%d,%.4f,%.4f,%.4f,%.4f,%.4f,", p.frame_index, p.label_id,
                    p.track_id, p.type.c_str(), p.dynamic ? 1 : 0, p.track_age, p.truth.x(), p.truth.y(), p.track.x(),
                    p.track.y(), p.error());
      out << buf;
      if (const auto& C = p.track_covariance) {
        std::snprintf(buf, sizeof buf, "%.6g,%.6g,%.6g,", (*C)(0, 0), (*C)(0, 1), (*C)(1, 1));
        out << buf;
      } else {
        out << ",,,";
      }
      if (const std::optional<double> nees = p.nees()) {
        std::snprintf(buf, sizeof buf, "%.4f", *nees);
        out << buf;
      }
      std::snprintf(buf, sizeof buf, ",%.2f\n", p.range_m);
      out << buf;
    }
  writeText(path, out.str());
}

void writeReport(const std::string& path, const Metrics& m, const std::vector<std::string>& plots) {
  writeText(path, reportMarkdown(m, plots));
}

std::string summaryLine(const Metrics& m) {
  std::ostringstream out;
  out << "eval:";
  const auto primary = m.ego.find(m.primary_source);
  if (primary == m.ego.end())
    out << " no ego trajectory";
  else if (!primary->second)
    out << " " << m.primary_source << " (no ground truth)";
  else
    out << " " << m.primary_source << " ATE " << cell(primary->second->ate_rmse_m, "%.3f") << " m, t_rel "
        << cell(primary->second->t_rel_pct ? primary->second->t_rel_pct : primary->second->t_rel_short_pct, "%.2f")
        << (primary->second->t_rel_pct ? " %" : " % (10-80 m)");
  if (primary != m.ego.end() && primary->second && primary->second->implausible_frames.value_or(0) > 0)
    out << "; ego speed jumps above 2 g on " << static_cast<int>(*primary->second->implausible_frames)
        << " scans (a lost or re-anchored ego: check the odometry's warnings)";
  if (m.odometry_checks && m.odometry_checks->disagreed > 0)
    out << "; landmarks and objects contradicted the odometry on " << m.odometry_checks->disagreed
        << " scans (down-weighted on " << m.odometry_checks->downweighted << ", by up to "
        << cell(m.odometry_checks->max_disagreement_m, "%.2f") << " m)";
  if (m.tracking)
    out << "; MOTA " << cell(m.tracking->clear.mota, "%.3f") << ", HOTA "
        << cell(m.tracking->hota ? Opt(m.tracking->hota->hota) : std::nullopt, "%.3f") << ", IDSW "
        << m.tracking->clear.idsw;
  else
    out << "; no tracking evaluation";
  for (const auto& [cls, k] : m.kitti) {
    out << "; " << cls << " sAMOTA " << cell(k.sweep.samota, "%.3f") << ", MOTA " << cell(k.all.mota, "%.3f") << ", IDSW "
        << k.all.idsw;
    // A line from a handful of labels is not the class's tracking quality: say how many it has.
    const int all = k.all.labels + k.all.ignored_labels;
    if (k.all.labels * 2 < all) out << " (KITTI protocol: " << k.all.labels << " of " << all << " labels in view)";
  }
  for (const char* module : {"detector", "odometry", "tracker", "backend"}) {
    const auto it = m.timing_ms.find(module);
    if (it != m.timing_ms.end()) out << "; " << module << " " << cell(it->second.mean(), "%.1f") << " ms";
  }
  return out.str();
}

void printSummary(std::ostream& out, const Metrics& m) {
  out << summaryLine(m) << "\n";
  if (!m.ego.empty()) out << "\n" << egoTable(m).render();
  if (m.tracking) out << "\n" << trackingTable(m).render();
  if (!m.tracking_by_class.empty())
    out << "\nAll around, per class (" << m.tracking->criterion.describe() << "):\n" << classTable(m).render();
  if (!m.kitti.empty()) out << "\nKITTI protocol (camera view):\n" << kittiTable(m).render() << kittiCoverageNotes(m);
  if (!m.timing_ms.empty()) out << "\n" << timingTable(m).render();
}

}  // namespace dlslot::eval
