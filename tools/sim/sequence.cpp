#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "calib.hpp"
#include "dlslot/kitti.hpp"
#include "dlslot/progress.hpp"
#include "oxts.hpp"
#include "sim.hpp"
#include "simulation.hpp"

namespace fs = std::filesystem;

namespace dlslot::sim {

namespace {

// times.txt, the vehicle's poses and the sensor's YAML calibration beside the .pcd scans. The
// vehicle frame is the ground point under the lidar (the lidar sits sensor.height_m above it).
void writePcdFolderFiles(const fs::path& dir, const Scenario& scenario, const std::vector<Pose>& lidar_poses,
                         const std::string& sequence) {
  const SensorSpec& s = scenario.sensor;
  {
    std::ofstream t(dir / "times.txt");
    for (size_t k = 0; k < lidar_poses.size(); ++k) {
      char line[32];
      std::snprintf(line, sizeof line, "%.6f\n", k * scenario.frame_period_s);
      t << line;
    }
  }
  Pose T_vehicle_lidar = Pose::Identity();
  T_vehicle_lidar.translation() << 0, 0, s.height_m;
  std::vector<Pose> vehicle;
  for (const Pose& T : lidar_poses) vehicle.push_back(T * T_vehicle_lidar.inverse());
  kitti::writePoses((dir / "poses.txt").string(), vehicle);
  std::ofstream c(dir / "calib.yaml");
  c << "# The simulated sensor (dlslot-sim, scenario " << scenario.name << ", seed " << scenario.seed << ").\n"
    << "sensor_to_vehicle:\n  translation: [0, 0, " << s.height_m << "]\n  rotation_rpy_deg: [0, 0, 0]\n"
    << "beams:\n";
  if (s.beams == kBeams)
    c << "  model: hdl64\n";
  else
    c << "  model: uniform\n  count: " << s.beams << "\n  elevation_deg: [" << s.top_elevation_deg << ", "
      << s.bottom_elevation_deg << "]\n";
  c << "range_m: [" << s.min_range_m << ", " << s.max_range_m << "]\n"
    << "vertical_angle_error_deg: " << s.vertical_angle_error_deg << "  # the points lie this far below their rays\n"
    << "camera_calib: ../training/calib/" << sequence << ".txt  # the detection files are in camera coordinates\n";
}

// The pipeline config's `lidar` section that describes these scans (config/dlslot.yaml's
// defaults are KITTI's, which the default sensor reproduces; a scenario that turns the vertical
// error or the motion distortion off would otherwise be corrected for what its scans do not have).
void writeLidarSection(const fs::path& file, const Scenario& scenario) {
  const SensorSpec& s = scenario.sensor;
  std::ofstream f(file);
  f << "# How dlslot-sim stored these scans (scenario " << scenario.name << "): the `lidar` section of the\n"
    << "# pipeline's config for them; dlslot-run --scenario merges it into the run's config.yaml.\n"
    << "lidar:\n"
    << "  sweep_period_s: " << (s.motion_distortion && !s.deskewed ? scenario.frame_period_s : 0.0) << "\n"
    << "  sweep_clockwise: true\n"
    << "  vertical_angle_error_deg: " << s.vertical_angle_error_deg << "\n";
  if (!f) throw std::runtime_error(file.string() + ": cannot write");
}

}  // namespace

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
  const fs::path pcd = root / "pcd";
  if (options.pcd_folder) {
    fs::remove_all(pcd);
    fs::create_directories(pcd);
  }
  ProgressLine progress("dlslot-sim " + scenario.name, frames);
  double points = 0;
  for (int k = 0; k < frames; ++k) {
    Simulation::FrameData fd = sim.frame(k, options.threads);
    char name[32];
    std::snprintf(name, sizeof name, "%06d.bin", k);
    kitti::writeVelodyne((velodyne / name).string(), fd.scan.points);
    if (options.pcd_folder) {
      pcl::PointCloud<pcl::PointXYZI> cloud;
      cloud.resize(fd.scan.points.cols());
      for (Eigen::Index i = 0; i < fd.scan.points.cols(); ++i) {
        auto& p = cloud[i];
        p.x = fd.scan.points(0, i), p.y = fd.scan.points(1, i), p.z = fd.scan.points(2, i), p.intensity = fd.scan.points(3, i);
      }
      std::snprintf(name, sizeof name, "%06d.pcd", k);
      if (pcl::io::savePCDFileBinary((pcd / name).string(), cloud) != 0)
        throw std::runtime_error((pcd / name).string() + ": cannot write");
    }
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
  writeLidarSection(root / "lidar.yaml", scenario);
  if (options.pcd_folder) writePcdFolderFiles(pcd, scenario, poses, sequence);

  stats.mean_points = points / frames;
  for (const kitti::LabelRow& r : labels) stats.labelled_tracks = std::max(stats.labelled_tracks, r.track_id + 1);
  for (size_t k = 1; k < poses.size(); ++k)
    stats.path_length_m += (poses[k].translation() - poses[k - 1].translation()).norm();
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (options.progress) progress.finish();
  return stats;
}

}  // namespace dlslot::sim
