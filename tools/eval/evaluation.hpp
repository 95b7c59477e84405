// One evaluation of a run: everything read from a log or from files goes into RunData, and
// evaluate() turns it into the metrics of the design brief (section 5).
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "clear_mot.hpp"
#include "dlslot/frame_accounting.hpp"
#include "dlslot/timing_stats.hpp"
#include "ego_metrics.hpp"
#include "hota.hpp"
#include "kitti_protocol.hpp"
#include "map_quality.hpp"
#include "tracking_frames.hpp"

namespace dlslot::eval {

// dlslot-eval --map: the mapper's static map and loops.
struct MapMetrics {
  MapScore score;                  // null SA/DA when the scans or labels are not there
  int loops_accepted = 0;
  std::optional<int> loops_false;  // null without ground-truth poses
  int keyframes = 0;
  int64_t map_points = 0;
  // |t| of (first^-1 last) minus the truth's, for the map trajectory and for SLOT's.
  std::optional<double> end_to_start_m, slot_end_to_start_m;
};

struct RunData {
  std::map<std::string, Trajectory> sources;  // the system's ego trajectories, by source name
  std::optional<Trajectory> truth;            // ground-truth T_world_lidar
  // Tracking: one entry per labelled scan the run covers, tracks in the scan's lidar frame.
  bool has_labels = false;
  bool has_tracks = false;
  bool track_velocities_given = false;  // tracks carry the system's own velocity estimate (SLOT_STATE)
  std::vector<TrackingFrame> tracking;
  // The KITTI protocol's input (label rows with their 2-D boxes, results rows): set when the
  // labels come from a KITTI label file.
  std::optional<KittiSequence> kitti;
  std::map<std::string, TimingStats> timing_ms;  // module -> per-frame processing time
  std::map<std::string, int64_t> frame_counts;   // channel -> messages in the log
  std::vector<std::string> notes;                // facts for the report (process health, warnings)
  std::optional<FrameAccounting> frames;         // where every played frame went (a recorded run)
  std::map<std::string, RssSummary> memory;      // process -> resident memory over the run
  std::map<std::string, int64_t> registration;   // the backend's per-object registrations by outcome
  std::optional<MapMetrics> map;                 // --map
  std::optional<OdometryChecks> odometry_checks;  // a recorded run with SLOT_STATE
};

struct EvalOptions {
  MatchCriterion distance;                                              // CLEAR MOT / HOTA, first line
  MatchCriterion iou{MatchCriterion::Kind::Iou3d};                      // second line
  double dynamic_speed_mps = 0.5;  // labels moving at least this fast count for the velocity RMSE
  // The labels' velocities are central differences over at most +- this (velocity.hpp); < 0:
  // chosen from the labels (labelVelocityHalfSpan).
  double label_velocity_half_span_s = -1.0;
  std::vector<std::string> classes;  // evaluated classes; empty = all
  KittiProtocolOptions kitti;
};

struct TrackingMetrics {
  MatchCriterion criterion;
  ClearMot clear;
  std::optional<Hota> hota;
  std::vector<VelocityGroup> velocity_groups;  // the velocity error by age, class, motion, stretch
};

struct Metrics {
  std::string primary_source;                               // "slot", else "odometry", else the first
  std::map<std::string, std::optional<EgoMetrics>> ego;     // per source; null without ground truth
  std::optional<TrackingMetrics> tracking, tracking_iou;    // null without labels or without tracks
  // The first line's matching per class (car, pedestrian, cyclist: those with labels), every label
  // all around the sensor: the table that scores a simulated scene whose people stand beside the
  // road, where the KITTI protocol sees only the few in the camera's image.
  std::map<std::string, ClearMot> tracking_by_class;
  std::map<std::string, KittiClassMetrics> kitti;           // the KITTI protocol per class; empty without it
  std::string velocity_frame;                               // how velocities were compared
  double label_velocity_half_span_s = 0.0;                  // the labels' central differences: +- this (0: neighbours)
  std::map<std::string, TimingStats> timing_ms;
  std::map<std::string, int64_t> frame_counts;
  std::vector<std::string> notes;
  std::optional<FrameAccounting> frames;
  std::map<std::string, RssSummary> memory;
  std::map<std::string, int64_t> registration;
  std::optional<MapMetrics> map;
  std::optional<OdometryChecks> odometry_checks;
};

std::string primarySource(const std::map<std::string, Trajectory>& sources);

// Throws std::invalid_argument when a trajectory and the ground truth share no frame.
Metrics evaluate(RunData run, const EvalOptions& options);

}  // namespace dlslot::eval
