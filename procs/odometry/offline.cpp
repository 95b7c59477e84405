#include "offline.hpp"

#include <cstdio>
#include <map>

#include "dlslot/input_error.hpp"
#include "dlslot/kitti.hpp"
#include "dlslot/progress.hpp"
#include "dlslot/timing_stats.hpp"
#include "lidar_odometry.hpp"

namespace dlslot::odometry {

namespace {

const char* statusName(Status s) {
  switch (s) {
    case Status::Ok: return "ok";
    case Status::FallbackFewPoints: return "fallback (few points)";
    case Status::FallbackSolveFailed: return "fallback (solve failed)";
    case Status::FirstFrame: return "first frame";
  }
  return "?";
}

}  // namespace

int runOffline(const OfflineOptions& opts, const OdometryConfig& cfg) {
  kitti::SequenceReader reader(opts.root, opts.sequence, opts.detections, opts.min_detection_score,
                               opts.frame_period_s);
  if (!reader.hasScans())
    throw InputError(opts.root, 0, "sequence " + opts.sequence + " has no scans (expected training/velodyne/" +
                                       opts.sequence + "/): odometry needs them");
  if (cfg.remove_detected_objects && opts.detections.empty())
    std::fprintf(stderr, "dlslot-odometry: mode aloam-filtered without --detections: nothing is removed\n");
  LidarOdometry odometry(cfg);
  std::vector<Pose> poses;
  std::vector<std::string> stage_order;
  std::map<std::string, TimingStats> stages;
  std::map<Status, int> statuses;
  long removed = 0, points = 0;
  int scan_to_scan_runs = 0;  // scans that needed scan-to-scan (every_scan false: few)
  // The velocity checks (lidar_odometry.cpp): scans checked, of those the ones that searched
  // motion hypotheses, weakly constrained, and re-anchored.
  int checked = 0, searched = 0, weak = 0, suspected = 0, reanchored = 0;
  // Per-scan statistics of registered scans, to compare simulated scans with real ones.
  TimingStats edges, planes, residuals, correspondences;
  ProgressLine progress("odometry " + opts.sequence + " (" + modeName(cfg.remove_detected_objects) + ")",
                        reader.size());
  for (int i = 0; i < reader.size(); ++i) {
    const OdometryResult r = odometry.process(reader.read(i), !opts.detections.empty());
    poses.push_back(r.T_world_lidar);
    ++statuses[r.status];
    if (!r.status_text.empty())  // fallbacks, and the first frame registered after them
      std::fprintf(stderr, "\nframe %d: %s: %s\n", i, statusName(r.status), r.status_text.c_str());
    removed += r.num_points_removed;
    if (r.status == Status::Ok) {
      edges.add(r.num_edge);
      planes.add(r.num_plane);
      residuals.add(1000.0 * r.residual_mean);
      correspondences.add(r.num_correspondences);
    }
    points += r.num_points_in;
    checked += r.velocity_checked ? 1 : 0;
    searched += r.motion_hypotheses > 0 ? 1 : 0;
    weak += r.degeneracy == Degeneracy::Confirmed || r.degeneracy == Degeneracy::Unchecked ? 1 : 0;
    suspected += r.degeneracy == Degeneracy::Suspected ? 1 : 0;
    reanchored += r.degeneracy == Degeneracy::Reanchored ? 1 : 0;
    for (const auto& [name, ms] : r.detail)
      if (name == "s2s_match" && ms > 0) ++scan_to_scan_runs;
    for (const auto& [name, ms] : r.timings) {
      if (!stages.count(name)) stage_order.push_back(name);
      stages[name].add(ms);
    }
    if (!opts.quiet) progress.update(i + 1);
  }
  if (!opts.quiet) progress.finish();
  kitti::writePoses(opts.out, poses);

  std::printf("wrote %zu poses to %s\n", poses.size(), opts.out.c_str());
  std::printf("mode %s: %.2f %% of the points removed as detected objects\n", modeName(cfg.remove_detected_objects),
              points > 0 ? 100.0 * removed / points : 0.0);
  for (const auto& [status, n] : statuses) std::printf("  %-26s %d frames\n", statusName(status), n);
  std::printf("scan-to-scan registration on %d of %d frames\n", scan_to_scan_runs, reader.size());
  std::printf("velocity checked on %d frames (motion hypotheses searched on %d), weakly constrained %d, "
              "disagreed once %d, re-anchored %d\n",
              checked, searched, weak, suspected, reanchored);
  std::printf("%-14s %9s %9s %9s   (ms per frame)\n", "stage", "mean", "p95", "max");
  for (const std::string& name : stage_order)
    std::printf("%-14s %9.2f %9.2f %9.2f\n", name.c_str(), stages[name].mean(), stages[name].percentile(95),
                stages[name].max());
  if (edges.count() > 0)
    std::printf("per scan (%zu registered): edge features %.0f, plane features %.0f, scan-to-map correspondences "
                "%.0f, residual mean %.2f mm\n",
                edges.count(), edges.mean(), planes.mean(), correspondences.mean(), residuals.mean());
  if (!poses.empty()) {
    const Eigen::Vector3d p = poses.back().translation();
    std::printf("final position %.3f %.3f %.3f m\n", p.x(), p.y(), p.z());
  }
  return 0;
}

}  // namespace dlslot::odometry
