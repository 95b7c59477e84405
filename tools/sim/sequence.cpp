#include <chrono>
#include <filesystem>

#include "calib.hpp"
#include "dlslot/kitti.hpp"
#include "dlslot/progress.hpp"
#include "oxts.hpp"
#include "sim.hpp"
#include "simulation.hpp"

namespace fs = std::filesystem;

namespace dlslot::sim {

SequenceStats writeSequence(const Scenario& scenario_in, int frames, uint64_t seed, const std::string& out_dir,
                            const std::string& sequence, const WriteOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  Scenario scenario = scenario_in;
  scenario.frames = frames;
  scenario.seed = seed;
  Simulation sim(scenario);

  const fs::path root(out_dir), training = root / "training";
  const fs::path velodyne = training / "velodyne" / sequence;
  // The sequence is written anew: scans left from an earlier, longer run into the same folder
  // would outnumber the new poses (the player then rejects the sequence).
  fs::remove_all(velodyne);
  for (const fs::path& dir : {velodyne, training / "label_02", training / "calib", training / "oxts",
                              training / "poses", root / "detections" / "sim"})
    fs::create_directories(dir);

  SequenceStats stats;
  stats.frames = frames;
  stats.objects = static_cast<int>(sim.motion().agents.size());
  stats.removed = sim.motion().removed;
  stats.ego_path_end_frame = sim.motion().ego_path_end_frame;
  std::vector<kitti::LabelRow> labels, detections;
  ProgressLine progress("dlslot-sim " + scenario.name, frames);
  double points = 0;
  for (int k = 0; k < frames; ++k) {
    Simulation::FrameData fd = sim.frame(k, options.threads);
    char name[32];
    std::snprintf(name, sizeof name, "%06d.bin", k);
    kitti::writeVelodyne((velodyne / name).string(), fd.scan.points);
    points += fd.scan.points.cols();
    labels.insert(labels.end(), fd.labels.begin(), fd.labels.end());
    detections.insert(detections.end(), fd.detections.begin(), fd.detections.end());
    if (options.progress) progress.update(k + 1, std::to_string(fd.scan.points.cols()) + " points");
  }
  const std::string file = sequence + ".txt";
  kitti::writeTrackingLabels((training / "label_02" / file).string(), labels);
  kitti::writeTrackingLabels((root / "detections" / "sim" / file).string(), detections);
  kitti::writeCalib((training / "calib" / file).string(), sim.calib());
  const std::vector<Pose> poses = sim.lidarPoses();
  kitti::writePoses((training / "poses" / file).string(), poses);
  kitti::writeOxts((training / "oxts" / file).string(),
                   simulatedOxts(poses, *sim.calib().T_velo_imu, scenario.frame_period_s));
  writeScenario((root / "scenario.yaml").string(), scenario);

  stats.mean_points = points / frames;
  for (const kitti::LabelRow& r : labels) stats.labelled_tracks = std::max(stats.labelled_tracks, r.track_id + 1);
  for (size_t k = 1; k < poses.size(); ++k)
    stats.path_length_m += (poses[k].translation() - poses[k - 1].translation()).norm();
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (options.progress) progress.finish();
  return stats;
}

}  // namespace dlslot::sim
