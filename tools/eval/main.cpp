// dlslot-eval: turns a recorded run (LCM log) or result files into the metrics of the design
// brief (section 5): metrics.json, report.md and plots, a summary on stdout; and exports a
// run's trajectories and tracks as files (KITTI / TUM formats).
#include <filesystem>
#include <iostream>
#include <limits>
#include <optional>
#include <set>
#include <sstream>

#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include "dlslot/input_error.hpp"
#include "dlslot/kitti.hpp"
#include "dlslot/node.hpp"
#include "dlslot/progress.hpp"
#include "evaluation.hpp"
#include "export.hpp"
#include "metrics_report.hpp"
#include "object_points.hpp"
#include "plots.hpp"
#include "run_log.hpp"

using namespace dlslot;
using namespace dlslot::eval;
namespace fs = std::filesystem;

namespace {

struct Options {
  std::string config = "config/dlslot.yaml";
  std::string log, kitti_root, sequence, calib;
  std::string traj, traj_format = "kitti", traj_name = "result";
  std::string gt_poses, gt_format = "kitti";
  std::string tracks;
  std::string out, export_dir;
  std::string map_dir;
  std::string classes;
  double match_distance = 2.0, min_iou = 0.25, dynamic_speed = 0.5, frame_period = 0.1, label_velocity_span = -1;
  double image_width = kitti::ImageSize().width, image_height = kitti::ImageSize().height;
  int track_max_unseen = 0;
  bool allow_missing_truth = false, quiet = false;
};

Channels readChannels(const std::string& config) {
  Channels channels;
  // The default config is optional (the built-in channel names are the shipped ones); a config
  // given explicitly must exist.
  if (config == Options().config && !fs::exists(config)) return channels;
  loadPipelineConfig(config, channels);  // every section known (a misspelt one is an error)
  return channels;
}

// Ground truth and calibration from the data set's own files.
struct DataSet {
  std::optional<kitti::Calib> calib;
  std::optional<Trajectory> poses;
  std::optional<std::vector<FrameTracks>> labels, dontcare;
  std::vector<kitti::LabelRow> label_rows;  // the label file as written (2-D boxes, truncation, occlusion)
  std::vector<double> stamps;
  int num_frames = 0;
};

DataSet readDataSet(const Options& o) {
  DataSet d;
  if (!o.kitti_root.empty()) {
    if (o.sequence.empty()) throw std::invalid_argument("--kitti needs --sequence");
    const kitti::SequenceReader reader(o.kitti_root, o.sequence, {}, -1e300, o.frame_period);
    const kitti::SequencePaths& p = reader.paths();
    d.calib = reader.calib();
    d.num_frames = reader.size();
    const std::vector<double> times = p.times.empty() ? std::vector<double>() : kitti::readTimes(p.times);
    for (int i = 0; i < d.num_frames; ++i) d.stamps.push_back(times.empty() ? i * o.frame_period : times[i]);
    if (reader.hasGroundTruthPoses()) {
      Trajectory t;
      for (int i = 0; i < d.num_frames; ++i) t.add(i, d.stamps[i], reader.groundTruthPoses()[i]);
      d.poses = t;
    }
    if (!p.labels.empty()) {
      d.dontcare.emplace();
      d.labels = readKittiTracks(p.labels, *d.calib, d.num_frames, &*d.dontcare);
      d.label_rows = kitti::readTrackingLabels(p.labels);
    }
  }
  if (!o.calib.empty()) d.calib = kitti::readCalib(o.calib);
  return d;
}

std::optional<Pose> camFromVelo(const DataSet& d) {
  return d.calib ? std::optional<Pose>(d.calib->T_cam_velo) : std::nullopt;
}

// The per-scan tracking input: labels, ignore regions and tracks of every labelled frame the run covers.
std::vector<TrackingFrame> trackingFrames(const std::map<int, RunLog::Labels>& labels,
                                          const std::map<int, RunLog::Tracks>& tracks, const std::set<int>& run_frames,
                                          const std::optional<Trajectory>& truth,
                                          const std::map<int, Pose>& ego_poses) {
  std::map<int, Pose> truth_pose;
  if (truth)
    for (size_t i = 0; i < truth->size(); ++i) truth_pose[truth->frames[i]] = truth->poses[i];
  std::vector<TrackingFrame> frames;
  for (const auto& [frame, l] : labels) {
    if (!run_frames.count(frame)) continue;
    TrackingFrame f;
    f.frame = frame;
    f.stamp = l.stamp;
    for (const Box& b : l.boxes) f.truth.push_back({b, std::nullopt, false});
    f.ignore = l.dontcare;
    if (const auto t = tracks.find(frame); t != tracks.end()) f.tracks = t->second.objects;
    if (const auto p = truth_pose.find(frame); p != truth_pose.end()) f.truth_pose = p->second;
    if (const auto p = ego_poses.find(frame); p != ego_poses.end()) f.ego_pose = p->second;
    frames.push_back(std::move(f));
  }
  return frames;
}

std::map<int, RunLog::Labels> labelsByFrame(const std::vector<FrameTracks>& labels,
                                            const std::vector<FrameTracks>& dontcare, const std::vector<double>& stamps) {
  std::map<int, RunLog::Labels> out;
  for (size_t i = 0; i < labels.size(); ++i) out[labels[i].frame] = {stamps.at(i), labels[i].boxes, dontcare[i].boxes};
  return out;
}

void requireSameLength(const Trajectory& est, const std::string& est_file, const Trajectory& gt, const std::string& gt_what) {
  if (est.size() != gt.size())
    throw InputError(est_file, 0, "has " + std::to_string(est.size()) + " poses but the ground truth (" + gt_what +
                                      ") has " + std::to_string(gt.size()) + ": trajectories of different lengths");
}

void exportRun(const std::string& dir, const RunLog* log, const RunData& run, const DataSet& data,
               const kitti::ImageSize& image) {
  fs::create_directories(dir);
  const std::optional<Pose> Tr = camFromVelo(data);
  std::map<std::string, Trajectory> trajectories = run.sources;
  if (run.truth) trajectories.emplace("groundtruth", *run.truth);
  for (const auto& [name, t] : trajectories) {
    writeTrajectory((fs::path(dir) / ("trajectory_" + name + "_kitti.txt")).string(), t, TrajectoryFormat::Kitti);
    writeTrajectory((fs::path(dir) / ("trajectory_" + name + "_tum.txt")).string(), t, TrajectoryFormat::Tum);
    if (Tr)
      writeTrajectory((fs::path(dir) / ("trajectory_" + name + "_kitti_cam.txt")).string(), t,
                      TrajectoryFormat::KittiCam, Tr);
  }
  if (!Tr) std::cerr << "dlslot-eval: no calibration (--kitti or --calib): kitti_cam trajectories and tracks not exported\n";
  if (log && !log->tracks.empty() && data.calib) {
    std::vector<FrameTracks> frames;
    for (const auto& [frame, t] : log->tracks) {
      FrameTracks f{frame, {}};
      for (const Object& o : t.objects) f.boxes.push_back(o.box);
      frames.push_back(std::move(f));
    }
    const ExportCount n = writeKittiTracks((fs::path(dir) / "tracks_kitti.txt").string(), frames, *data.calib, image);
    std::cerr << "dlslot-eval: tracks_kitti.txt: " << n.written << " rows; " << n.outside_image
              << " track boxes outside the camera image left out\n";
  }
}

// The KITTI protocol's input for one sequence: the label file's rows and the results rows, either
// read from a results file or made from the run's tracks with kitti::resultRow (boxes outside the
// camera image are not scored, as they would not be written to a results file).
KittiSequence kittiSequence(const Options& o, const DataSet& data, const std::map<int, RunLog::Tracks>& tracks,
                            const std::set<int>& run_frames, const kitti::ImageSize& image,
                            std::vector<std::string>& notes) {
  KittiSequence seq;
  seq.name = o.sequence;
  seq.labels = data.label_rows;
  for (int f : run_frames)
    if (f >= 0 && f < data.num_frames) seq.frames.push_back(f);
  if (!o.tracks.empty()) {
    seq.tracks = kitti::readTrackingLabels(o.tracks);
    int flat = 0, outside = 0;
    for (const kitti::LabelRow& r : seq.tracks) {
      flat += !(r.bbox2d[3] - r.bbox2d[1] > 0);
      outside += !kitti::projectToImage(r.box, *data.calib, image);
    }
    if (flat > 0) {
      notes.push_back("KITTI protocol: " + std::to_string(flat) + " of " + std::to_string(seq.tracks.size()) +
                      " rows of " + o.tracks +
                      " have no 2-D box (height <= 0): the devkit and AB3DMOT's script never count such a row as a "
                      "false positive, so these numbers flatter the tracker; the 2-D box must be the 3-D box "
                      "projected with P2 (kitti::resultRow)");
      std::cerr << "dlslot-eval: warning: " << notes.back() << "\n";
    }
    if (outside > 0)
      notes.push_back("KITTI protocol: " + std::to_string(outside) + " rows of " + o.tracks +
                      " have a 3-D box outside the camera image; scored by their 2-D box, as the devkit does");
  } else {
    int outside = 0;
    for (const auto& [frame, t] : tracks)
      for (const Object& obj : t.objects) {
        if (std::optional<kitti::LabelRow> row = kitti::resultRow(frame, obj.box, *data.calib, image))
          seq.tracks.push_back(std::move(*row));
        else
          ++outside;
      }
    notes.push_back("KITTI protocol: " + std::to_string(seq.tracks.size()) + " track boxes in the camera image scored, " +
                    std::to_string(outside) + " outside it not scored");
  }
  return seq;
}

std::vector<std::string> kittiClasses(const std::vector<std::string>& classes) {
  std::vector<std::string> out;
  for (const std::string& c : classes)
    if (c == "Car" || c == "Pedestrian" || c == "Cyclist") out.push_back(c);
  return out;
}

void addProcessNotes(const RunLog& log, RunData& run) {
  for (const auto& [name, s] : log.last_status) {
    std::ostringstream n;
    n << "process " << name << ": " << s.frames_handled << " frames, " << s.decode_errors << " decode errors, "
      << s.frame_gaps << " frame gaps, " << s.timeouts << " timeouts, " << s.errors << " errors"
      << (s.last_warning.empty() ? "" : "; last warning: " + s.last_warning);
    run.notes.push_back(n.str());
  }
}

// The mapper's keyframes (map_keyframes.txt: frame, kept, removed, T_map_lidar 3x4, T_map_lidar at
// insertion 3x4) or accepted
// loops (map_loops.txt: query, match, accepted, ..., T_match_query 3x4).
std::vector<std::vector<double>> readNumberRows(const std::string& path, size_t min_fields, size_t max_fields = 18) {
  std::ifstream in(path);
  if (!in) throw InputError(path, 0, "cannot open");
  std::vector<std::vector<double>> rows;
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream ls(line);
    std::vector<double> v;
    double x;
    while (v.size() < max_fields && ls >> x) v.push_back(x);
    if (v.size() < min_fields || !std::all_of(v.begin(), v.end(), [](double d) { return std::isfinite(d); }))
      throw InputError(path, n, "expected at least " + std::to_string(min_fields) + " finite numbers");
    rows.push_back(std::move(v));
  }
  return rows;
}

Pose poseFrom12(const std::vector<double>& v, size_t at) {
  Pose T = Pose::Identity();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) T.matrix()(r, c) = v[at + 4 * r + c];
  T.linear() = Eigen::Quaterniond(T.rotation()).normalized().toRotationMatrix();
  return T;
}

// dlslot-eval --map DIR: the mapper's trajectory as source "map", the map's SA / DA / AA against
// the labels (when the data set has scans and labels), its loops against the true poses.
void addMap(const Options& o, const DataSet& data, RunData& run) {
  const fs::path dir(o.map_dir);
  MapMetrics mm;
  run.sources["map"] = readTrajectory((dir / "trajectory_map_kitti.txt").string(), TrajectoryFormat::Kitti, std::nullopt,
                                      o.frame_period);
  std::map<int, Pose> map_pose, truth_pose;
  {
    const Trajectory& t = run.sources["map"];
    for (size_t i = 0; i < t.size(); ++i) map_pose[t.frames[i]] = t.poses[i];
  }
  if (run.truth) {
    const Trajectory truth = inWorldOf(*run.truth, run.sources["map"]);
    for (size_t i = 0; i < truth.size(); ++i) truth_pose[truth.frames[i]] = truth.poses[i];
  }
  // Loops.
  int accepted = 0, wrong = 0;
  for (const auto& r : readNumberRows((dir / "map_loops.txt").string(), 18)) {
    if (r[2] != 1) continue;
    ++accepted;
    const auto q = truth_pose.find(static_cast<int>(r[0])), m = truth_pose.find(static_cast<int>(r[1]));
    if (q != truth_pose.end() && m != truth_pose.end()) wrong += isFalseLoop(poseFrom12(r, 6), m->second.inverse() * q->second);
  }
  mm.loops_accepted = accepted;
  if (!truth_pose.empty()) mm.loops_false = wrong;
  // End-to-start: how far the last scan's pose relative to the first is from the truth's (what a
  // loop that returns to its start must get right).
  auto endToStart = [&](const Trajectory& t) -> std::optional<double> {
    if (t.size() < 2 || !truth_pose.count(t.frames.front()) || !truth_pose.count(t.frames.back())) return std::nullopt;
    const Pose est = t.poses.front().inverse() * t.poses.back();
    const Pose gt = truth_pose[t.frames.front()].inverse() * truth_pose[t.frames.back()];
    return (est.translation() - gt.translation()).norm();
  };
  mm.end_to_start_m = endToStart(run.sources["map"]);
  if (run.sources.count("slot")) mm.slot_end_to_start_m = endToStart(run.sources["slot"]);
  // The map.
  pcl::PointCloud<pcl::PointXYZI> cloud;
  const std::string pcd = (dir / "map.pcd").string();
  if (pcl::io::loadPCDFile(pcd, cloud) != 0) throw InputError(pcd, 0, "not a PCD file PCL can read");
  PointCloud map_points(4, static_cast<Eigen::Index>(cloud.size()));
  for (size_t i = 0; i < cloud.size(); ++i) map_points.col(static_cast<Eigen::Index>(i)) << cloud[i].x, cloud[i].y, cloud[i].z, cloud[i].intensity;
  mm.map_points = static_cast<int64_t>(cloud.size());
  const auto keyframe_rows = readNumberRows((dir / "map_keyframes.txt").string(), 15, 27);
  mm.keyframes = static_cast<int>(keyframe_rows.size());
  MapTruthOptions opt;
  {
    ConfigSection root = loadConfig(findConfigFile(o.config));
    ConfigSection mapper = root.section("mapper");
    mapper.get("map_voxel_m", opt.voxel_m);
    mapper.get("min_range_m", opt.min_range_m);
    mapper.get("max_range_m", opt.max_range_m);
    opt.sweep = LidarConfig::read(root.section("lidar")).sweep;
  }
  mm.score.voxel_m = opt.voxel_m;
  if (!o.kitti_root.empty()) {
    const kitti::SequenceReader reader(o.kitti_root, o.sequence, {}, -1e300, o.frame_period);
    if (reader.hasScans() && reader.hasLabels()) {
      std::map<int, std::vector<Box>> labels;
      for (int f = 0; f < reader.size(); ++f) labels[f] = reader.read(f).labels;
      // Real KITTI labels cover what camera 2 sees; the simulator labels all around. Told apart by the
      // labels themselves (the layout does not tell: both are tracking folders): a label behind the
      // camera exists only where the labelling is all around.
      bool all_around = false;
      const Pose T_cam_lidar = reader.calib().T_rect_velo();
      for (const auto& [f, boxes] : labels)
        for (const Box& b : boxes) all_around = all_around || (T_cam_lidar * b.center).z() < 0;
      if (!all_around) {
        // Real KITTI labels: only what camera 2 sees (its horizontal field of view from P2).
        const kitti::Calib& calib = reader.calib();
        opt.T_cam_lidar = calib.T_rect_velo();
        const double fx = calib.P[2](0, 0);
        opt.camera_half_fov_rad = fx > 0 ? std::atan(0.5 * kitti::ImageSize().width / fx) : 0.0;
      }
      std::vector<MapKeyframe> keyframes;
      for (const auto& r : keyframe_rows) {
        MapKeyframe k;
        k.frame = static_cast<int>(r[0]);
        if (k.frame < 0 || k.frame >= reader.size()) throw InputError((dir / "map_keyframes.txt").string(), 0, "frame outside the sequence");
        k.T_map_lidar = poseFrom12(r, 3);
        if (r.size() >= 27) k.T_grid_lidar = poseFrom12(r, 15);  // the pose its points were inserted with
        const Frame f = reader.read(k.frame);
        k.scan = f.scan;
        k.labels = movingLabels(labels, k.frame, o.frame_period);
        k.dontcare = f.dontcare;
        keyframes.push_back(std::move(k));
      }
      // Which tracks move: in the true world when there is one, else in the map's (the slice's approximate poses are
      // not read as truth).
      const std::set<int> moving = movingTracks(labels, truth_pose.empty() ? map_pose : truth_pose, opt.moving_span_m);
      mm.score = scoreMap(map_points, keyframes, moving, opt);
      run.notes.push_back("map: " + std::to_string(moving.size()) + " labelled tracks move (centres span > " +
                          std::to_string(opt.moving_span_m) + " m in the " + (truth_pose.empty() ? "map's" : "true") +
                          " world); " + (opt.T_cam_lidar ? "scored in camera 2's field of view" : "scored all around"));
    } else {
      run.notes.push_back("map: SA / DA not scored: the sequence has no scans or no labels");
    }
  } else {
    run.notes.push_back("map: SA / DA not scored: no --kitti ROOT --sequence S for the scans and labels");
  }
  run.map = mm;
}

// --object-points: the labelled objects' point counts of one sequence, by class and range.
int reportObjectPoints(const Options& o) {
  if (o.kitti_root.empty() || o.sequence.empty()) throw std::invalid_argument("--object-points needs --kitti ROOT --sequence S");
  const kitti::SequenceReader reader(o.kitti_root, o.sequence);
  if (!reader.hasScans() || !reader.hasLabels())
    throw std::invalid_argument(o.kitti_root + " sequence " + o.sequence + ": --object-points needs scans and labels");
  const ObjectPointOptions options;
  std::vector<ObjectPoints> samples;
  ProgressLine progress("object points, " + o.sequence, reader.size());
  for (int i = 0; i < reader.size(); ++i) {
    const Frame f = reader.read(i);
    const std::vector<ObjectPoints> counted = countObjectPoints(f.index, f.scan, f.labels, options);
    samples.insert(samples.end(), counted.begin(), counted.end());
    progress.update(i + 1);
  }
  progress.finish(std::to_string(samples.size()) + " labelled objects");
  std::cout << objectPointTable(summariseObjectPoints(samples, options));
  if (!o.out.empty()) {
    std::filesystem::create_directories(o.out);
    writeObjectPointsCsv(o.out + "/object_points.csv", samples);
    std::cout << "wrote " << o.out << "/object_points.csv\n";
  }
  return 0;
}

int run(int argc, char** argv) {
  Options o;
  CommandLine cl("dlslot-eval",
                 "Evaluates a recorded run (--log) or result files (--traj, --tracks) against ground truth; writes "
                 "metrics.json, report.md and plots (--out) and exports trajectories and tracks (--export).");
  cl.option("--config", &o.config, "config file, for the channel names (default config/dlslot.yaml)");
  cl.option("--log", &o.log, "recorded run (lcm-logger file)");
  cl.option("--kitti", &o.kitti_root, "data set root (KITTI tracking or odometry layout): ground truth and calibration");
  cl.option("--sequence", &o.sequence, "sequence name, e.g. 0000");
  cl.option("--calib", &o.calib, "calibration file (instead of --kitti) for kitti_cam files and tracks");
  cl.option("--traj", &o.traj, "estimated trajectory file");
  cl.option("--traj-format", &o.traj_format, "kitti (lidar 3x4), kitti_cam (camera-0 3x4) or tum (default kitti)");
  cl.option("--traj-name", &o.traj_name, "source name of --traj in the report (default result)");
  cl.option("--gt-poses", &o.gt_poses, "ground-truth trajectory file (default: from --kitti or the log)");
  cl.option("--gt-format", &o.gt_format, "format of --gt-poses (default kitti)");
  cl.option("--tracks", &o.tracks, "tracks in the KITTI tracking result format (needs --kitti for labels and calib)");
  cl.option("--out", &o.out, "write DIR/metrics.json, DIR/report.md, DIR/plots/*.png");
  cl.option("--export", &o.export_dir, "write DIR/trajectory_<source>_<format>.txt and DIR/tracks_kitti.txt");
  cl.option("--map", &o.map_dir,
            "the mapper's output directory (map.pcd, map_keyframes.txt, map_loops.txt, trajectory_map_kitti.txt): "
            "map.sa/da/aa against the labels, loops against the true poses, the map trajectory as source 'map'");
  cl.option("--classes", &o.classes, "evaluated classes, comma-separated (default: all)");
  cl.option("--match-distance", &o.match_distance, "centre-distance gate in metres (default 2)");
  cl.option("--min-iou", &o.min_iou, "3D IoU gate of the second line and of the KITTI protocol (default 0.25)");
  cl.option("--dynamic-speed", &o.dynamic_speed, "labels at least this fast (m/s) are dynamic (default 0.5)");
  cl.option("--label-velocity-span", &o.label_velocity_span,
            "labels' velocities: central differences over at most +- this many seconds (default: 0.5 for a "
            "human's labels, which jitter; neighbouring frames for the simulator's exact ones)");
  cl.option("--track-max-unseen", &o.track_max_unseen,
            "SLOT_STATE tracks not observed for more frames than this are not output (default 0)");
  cl.option("--image-width", &o.image_width, "image_02 width in pixels for 2-D boxes (default 1242)");
  cl.option("--image-height", &o.image_height, "image_02 height in pixels for 2-D boxes (default 375)");
  cl.option("--frame-period", &o.frame_period, "seconds per scan for files without timestamps (default 0.1)");
  cl.flag("--allow-missing-truth", &o.allow_missing_truth, "report timing alone when there is no ground truth");
  cl.flag("--quiet", &o.quiet, "no summary on stdout");
  bool object_points = false;
  cl.flag("--object-points", &object_points,
          "only the points inside each labelled box, by class and range (needs --kitti ROOT --sequence S; "
          "--out DIR adds object_points.csv): how densely the lidar samples the objects, to compare data sets");
  if (!cl.parse(argc, argv)) return 0;
  if (object_points) return reportObjectPoints(o);
  if (o.log.empty() && o.traj.empty() && o.tracks.empty())
    throw std::invalid_argument("nothing to evaluate: give --log RUN.lcmlog, --traj FILE or --tracks FILE\n" + cl.usage());
  if (!o.tracks.empty() && o.kitti_root.empty())
    throw std::invalid_argument("--tracks needs --kitti ROOT --sequence S (labels and calibration)");

  const Channels channels = readChannels(o.config);
  const DataSet data = readDataSet(o);
  RunData run;
  std::optional<RunLog> log;
  std::set<int> run_frames;
  std::map<int, RunLog::Labels> labels;
  std::map<int, RunLog::Tracks> tracks;
  std::map<int, Pose> ego_poses;  // the system's own pose per frame, for the tracks

  if (!o.log.empty()) {
    log = readRunLog(o.log, channels, o.track_max_unseen);
    run.sources = log->sources;
    if (!log->truth.empty()) run.truth = log->truth;
    labels = log->labels;
    tracks = log->tracks;
    run_frames = log->frames;
    run.has_tracks = log->frame_counts[channels.slot_state] > 0;
    run.track_velocities_given = true;
    for (const auto& [frame, t] : tracks) ego_poses[frame] = t.ego;
    run.timing_ms = log->timing_ms;
    run.frame_counts = log->frame_counts;
    run.odometry_checks = log->odometry_checks;
    addProcessNotes(*log, run);
    std::vector<std::string> pipeline;
    for (const std::string p : {"detector", "odometry", "tracker", "backend", "renderer", "mapper"})
      if (log->last_status.count(p)) pipeline.push_back(p);
    run.frames = accountFrames(log->last_status, log->frame_counts[channels.scan], pipeline);
    // The backend counts its per-object registrations by outcome (registration_<outcome>).
    if (const auto backend = log->last_status.find("backend"); backend != log->last_status.end())
      for (int i = 0; i < backend->second.num_counters; ++i) {
        const std::string& name = backend->second.counter_names[i];
        if (name.rfind("registration_", 0) == 0) run.registration[name.substr(13)] = backend->second.counter_values[i];
      }
    for (const auto& [process, samples] : log->rss_kb)
      if (const auto r = summarizeRss(samples)) run.memory[process] = *r;
    if (!log->refused.empty()) {
      std::ostringstream n;
      int64_t total = 0;
      for (const auto& [what, count] : log->refused) {
        n << (total ? ", " : "") << what << " " << count;
        total += count;
      }
      const std::string note = "log: " + std::to_string(total) + " events refused and skipped (" + n.str() + ")";
      std::cerr << "dlslot-eval: " << o.log << ": " << note << "\n";
      run.notes.push_back(note);
    }
  }
  // Data-set files win over what the log carried.
  if (data.poses) run.truth = data.poses;
  if (data.labels) labels = labelsByFrame(*data.labels, *data.dontcare, data.stamps);
  if (!o.gt_poses.empty())
    run.truth = readTrajectory(o.gt_poses, parseTrajectoryFormat(o.gt_format), camFromVelo(data), o.frame_period);

  if (!o.map_dir.empty()) addMap(o, data, run);
  if (!o.traj.empty()) {
    Trajectory t = readTrajectory(o.traj, parseTrajectoryFormat(o.traj_format), camFromVelo(data), o.frame_period);
    if (run.truth) requireSameLength(t, o.traj, *run.truth, o.gt_poses.empty() ? "the data set's poses" : o.gt_poses);
    if (o.log.empty())
      for (size_t i = 0; i < t.size(); ++i) ego_poses[t.frames[i]] = t.poses[i];
    run.sources[o.traj_name] = std::move(t);
  }
  if (!o.tracks.empty()) {
    for (const FrameTracks& f : readKittiTracks(o.tracks, *data.calib, data.num_frames)) {
      RunLog::Tracks& t = tracks[f.frame];
      t.stamp = data.stamps.at(f.frame);
      t.objects.clear();
      for (const Box& b : f.boxes) t.objects.push_back({b, std::nullopt, false});
    }
    run.has_tracks = true;
    run.track_velocities_given = false;
    for (int i = 0; i < data.num_frames; ++i) run_frames.insert(i);
  }

  run.has_labels = !labels.empty();
  run.tracking = trackingFrames(labels, tracks, run_frames, run.truth, ego_poses);
  if (!run.truth && !run.has_labels) {
    const std::string what =
        "no ground truth: " + std::string(o.log.empty() ? "" : "the log has no GROUND_TRUTH messages; ") +
        "give --kitti ROOT --sequence S or --gt-poses FILE";
    if (o.log.empty() || !o.allow_missing_truth)
      throw InputError(o.log.empty() ? (o.traj.empty() ? o.tracks : o.traj) : o.log, 0,
                       what + (o.log.empty() ? "" : " (or --allow-missing-truth to report timing alone)"));
    std::cerr << "dlslot-eval: " << what << "; ego and tracking metrics are null\n";
  }

  const kitti::ImageSize image{o.image_width, o.image_height};
  if (run.has_tracks && !data.label_rows.empty())
    run.kitti = kittiSequence(o, data, tracks, run_frames, image, run.notes);
  else if (run.has_tracks && run.has_labels)
    run.notes.push_back("KITTI protocol not evaluated: it needs the label file (--kitti ROOT --sequence S) for the "
                        "2-D boxes, truncation, occlusion and DontCare regions");
  if (!o.export_dir.empty()) exportRun(o.export_dir, log ? &*log : nullptr, run, data, image);

  EvalOptions opt;
  opt.distance.max_distance_m = o.match_distance;
  opt.iou.min_iou = o.min_iou;
  opt.dynamic_speed_mps = o.dynamic_speed;
  opt.label_velocity_half_span_s = o.label_velocity_span;
  opt.classes = splitList(o.classes);
  opt.kitti.min_iou = o.min_iou;
  opt.kitti.classes = kittiClasses(opt.classes);
  const std::map<std::string, Trajectory> sources = run.sources;
  const std::optional<Trajectory> truth = run.truth;
  const Metrics metrics = evaluate(std::move(run), opt);

  if (!o.out.empty()) {
    const fs::path out(o.out);
    fs::create_directories(out / "plots");
    std::vector<std::string> plots;
    if (!sources.empty()) {
      // The ground truth drawn in the primary source's world (they differ when the run started
      // later in the sequence).
      const Trajectory& primary = sources.at(primarySource(sources));
      const std::optional<Trajectory> drawn_truth =
          truth ? std::optional<Trajectory>(inWorldOf(*truth, primary)) : std::nullopt;
      plotTrajectories((out / "plots" / "trajectories.png").string(), sources, drawn_truth);
      plots.push_back("plots/trajectories.png");
      if (truth) {
        plotErrorOverDistance((out / "plots" / "error_over_distance.png").string(), sources, *truth);
        plots.push_back("plots/error_over_distance.png");
      }
    }
    if (metrics.tracking && metrics.tracking->clear.velocity_pairs > 0) {
      // Bins of at least 10 pairs: a bin's RMSE is then uncertain by about a fifth of itself.
      const std::vector<VelocityPair>& pairs = metrics.tracking->clear.velocities;
      plotVelocityErrorByRange((out / "plots" / "velocity_error_by_range.png").string(),
                               velocityErrorByRange(pairs, 10.0, 0, 4, 10),
                               velocityErrorByRange(pairs, 10.0, 5, std::numeric_limits<int>::max(), 10));
      plots.push_back("plots/velocity_error_by_range.png");
      constexpr int kLastAge = 20;  // the report's oldest age group starts there
      plotVelocityErrorByAge((out / "plots" / "velocity_error_by_age.png").string(),
                             velocityErrorByAge(pairs, kLastAge, 10), kLastAge);
      plots.push_back("plots/velocity_error_by_age.png");
    }
    writeMetricsJson((out / "metrics.json").string(), metrics);
    writeVelocityErrorsCsv((out / "velocity_errors.csv").string(), metrics);
    writeReport((out / "report.md").string(), metrics, plots);
  }
  if (!o.quiet) printSummary(std::cout, metrics);
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return runMain("dlslot-eval", [&] { return run(argc, argv); }); }
