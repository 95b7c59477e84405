// dlslot-eval end to end: a run written here as an LCM log (lcm::LogFile, write mode) and a small
// KITTI tracking layout, evaluated and exported by the executable; bad inputs fail clearly.
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

#include "dlslot/associations_t.hpp"
#include "dlslot/convert.hpp"
#include "dlslot/ground_truth_t.hpp"
#include "dlslot/kitti.hpp"
#include "dlslot/odometry_t.hpp"
#include "dlslot/point_cloud_t.hpp"
#include "dlslot/process_status_t.hpp"
#include "dlslot/slot_state_t.hpp"
#include "export.hpp"
#include "text_file.hpp"
#include "trajectory.hpp"

using namespace dlslot;
using dlslot::test::readText;
namespace fs = std::filesystem;

namespace {

constexpr int kFrames = 30;

Pose truePose(int t) {  // the ego drives 1 m a frame along x while turning slowly
  Pose T = Pose::Identity();
  T.linear() = Eigen::AngleAxisd(0.01 * t, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() << 1.0 * t, 0.02 * t * t, 0;
  return T;
}

// Car 1 drives 15 m/s along world x; pedestrian 2 stands still.
std::vector<Box> worldObjects(int t) {
  Box car;
  car.center << 10 + 1.5 * t, 5, 0.8;
  car.size << 4.2, 1.8, 1.6;
  car.type = "Car";
  car.id = 1;
  Box ped;
  ped.center << 20, -5, 0.9;
  ped.size << 0.8, 0.6, 1.8;
  ped.type = "Pedestrian";
  ped.id = 2;
  return {car, ped};
}

kitti::Calib testCalib() {
  kitti::Calib c;
  Pose Tr = Pose::Identity();
  Tr.linear() << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  Tr.translation() << -0.004, -0.076, -0.27;
  c.T_cam_velo = Tr;
  c.P[2] << 721.5, 0, 609.6, 44.9, 0, 721.5, 172.9, 0.2, 0, 0, 1, 0.003;
  return c;
}

template <class Msg>
void write(lcm::LogFile& log, const std::string& channel, const Msg& msg, int64_t utime) {
  std::vector<uint8_t> buf(msg.getEncodedSize());
  msg.encode(buf.data(), 0, static_cast<int>(buf.size()));
  lcm::LogEvent ev;
  ev.timestamp = utime;
  ev.channel = channel;
  ev.datalen = static_cast<int32_t>(buf.size());
  ev.data = buf.data();
  ASSERT_EQ(log.writeEvent(&ev), 0);
}

stage_timing_t timing(const std::string& name, double ms) {
  stage_timing_t s;
  s.name = name;
  s.ms = ms;
  return s;
}

// A complete run: scans, ground truth, odometry (drifting sideways 1 cm a frame), associations,
// and a backend that is exact (ego pose and tracks) plus one stale track.
void writeRun(const std::string& path, bool with_truth = true) {
  lcm::LogFile log(path, "w");
  ASSERT_TRUE(log.good());
  for (int t = 0; t < kFrames; ++t) {
    const int64_t utime = 100000 * t;
    const Pose T = truePose(t);
    point_cloud_t scan;
    scan.utime = utime;
    scan.frame = t;
    scan.sequence = "0000";
    toMsg(PointCloud::Random(4, 10), scan);
    write(log, "LIDAR_SCAN", scan, utime);
    if (with_truth) {
      ground_truth_t gt;
      gt.utime = utime;
      gt.frame = t;
      gt.has_pose = true;
      gt.pose = toMsg(T);
      for (const Box& b : worldObjects(t)) gt.boxes.push_back(toMsg(b.transformed(T.inverse())));
      gt.num_boxes = static_cast<int32_t>(gt.boxes.size());
      Box dontcare;
      dontcare.center << 0, 30, 1;
      dontcare.size << 6, 6, 3;
      dontcare.type = "DontCare";
      gt.dontcare.push_back(toMsg(dontcare.transformed(T.inverse())));
      gt.num_dontcare = 1;
      write(log, "GROUND_TRUTH", gt, utime);
    }
    odometry_t odo{};
    odo.utime = utime;
    odo.frame = t;
    Pose drifted = T;
    drifted.translation().y() += 0.01 * t;
    odo.pose = toMsg(drifted);
    odo.delta = toMsg(Pose::Identity());
    odo.timings = {timing("features", 2.0), timing("total", 10.0 + t % 3)};
    odo.num_timings = 2;
    write(log, "ODOMETRY", odo, utime);
    associations_t assoc{};
    assoc.utime = utime;
    assoc.frame = t;
    assoc.ego_pose = toMsg(T);
    assoc.timings = {timing("total", 1.0)};
    assoc.num_timings = 1;
    write(log, "ASSOCIATIONS", assoc, utime);
    slot_state_t slot{};
    slot.utime = utime;
    slot.frame = t;
    slot.mode = "slot";
    slot.ego_pose = toMsg(T);
    const std::vector<Box> objects = worldObjects(t);
    for (size_t k = 0; k < objects.size(); ++k) {
      track_t tr{};
      tr.id = 100 + static_cast<int>(k);
      tr.type = objects[k].type;
      tr.pose = toMsg(objects[k].pose());
      for (int i = 0; i < 3; ++i) tr.size[i] = objects[k].size[i];
      tr.velocity[0] = k == 0 ? 15.0 : 0.0;
      if (k == 0) tr.velocity_covariance[0] = tr.velocity_covariance[4] = tr.velocity_covariance[8] = 0.04;
      tr.is_dynamic = k == 0;
      tr.last_seen_frame = t;
      slot.tracks.push_back(tr);
    }
    track_t stale{};
    stale.id = 300;
    stale.type = "Car";
    stale.pose = toMsg(Pose(Eigen::Translation3d(T.translation() + Eigen::Vector3d(0, -15, 0))));
    stale.size[0] = 4;
    stale.size[1] = 2;
    stale.size[2] = 1.5;
    stale.last_seen_frame = t - 5;  // not observed lately: not part of this frame's output
    slot.tracks.push_back(stale);
    slot.num_tracks = static_cast<int32_t>(slot.tracks.size());
    slot.timings = {timing("total", 5.0), timing("solve", 4.0)};
    slot.num_timings = 2;
    // The backend's odometry test: untested on the first frame, contradicted on frames 10 and 11.
    const bool contradicted = t == 10 || t == 11;
    slot.odometry_check = t == 0 ? slot_state_t::ODOMETRY_UNTESTED
                                 : contradicted ? slot_state_t::ODOMETRY_DOWNWEIGHTED : slot_state_t::ODOMETRY_CONSISTENT;
    slot.odometry_disagreement_m = contradicted ? 2.0 + 0.1 * (t - 10) : 0.01;
    slot.odometry_chi2 = contradicted ? 900.0 : 1.0;
    slot.odometry_inflation = contradicted ? 5000.0 : 1.0;
    write(log, "SLOT_STATE", slot, utime);
  }
  process_status_t status{};
  status.name = "odometry";
  status.frames_handled = kFrames;
  write(log, "PROCESS_STATUS", status, 100000 * kFrames);
  process_status_t backend{};
  backend.name = "backend";
  backend.frames_handled = kFrames;
  backend.counter_names = {"registration_measured", "registration_too_few_points", "landmarks"};
  backend.counter_values = {7, 3, 12};
  backend.num_counters = 3;
  write(log, "PROCESS_STATUS", backend, 100000 * kFrames + 1);
}

// A KITTI tracking layout with the same ground truth (poses in the lidar frame, labels in camera).
void writeKittiLayout(const fs::path& root) {
  const fs::path training = root / "training";
  for (const char* d : {"velodyne/0000", "calib", "label_02", "poses"}) fs::create_directories(training / d);
  const kitti::Calib calib = testCalib();
  kitti::writeCalib((training / "calib" / "0000.txt").string(), calib);
  std::vector<Pose> poses;
  std::vector<kitti::LabelRow> rows;
  for (int t = 0; t < kFrames; ++t) {
    char name[32];
    std::snprintf(name, sizeof name, "%06d.bin", t);
    kitti::writeVelodyne((training / "velodyne" / "0000" / name).string(), PointCloud::Zero(4, 5));
    poses.push_back(truePose(t));
    for (const Box& b : worldObjects(t)) {
      kitti::LabelRow r;
      r.frame = t;
      r.track_id = b.id;
      r.type = b.type;
      r.box = kitti::lidarToCamera(b.transformed(truePose(t).inverse()), calib);
      rows.push_back(r);
    }
  }
  kitti::writePoses((training / "poses" / "0000.txt").string(), poses);
  kitti::writeTrackingLabels((training / "label_02" / "0000.txt").string(), rows);
}

struct Result {
  int code = -1;
  std::string out, err;
};

class EvalLog : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("dlslot_eval_log_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  Result eval(const std::string& args) {
    const std::string out = (dir_ / "stdout").string(), err = (dir_ / "stderr").string();
    const std::string cmd = std::string(DLSLOT_BIN_DIR) + "/dlslot-eval --config " + DLSLOT_SOURCE_DIR +
                            "/config/dlslot.yaml " + args + " > " + out + " 2> " + err;
    const int status = std::system(cmd.c_str());
    Result r;
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = slurp(out);
    r.err = slurp(err);
    return r;
  }
  static std::string slurp(const fs::path& p) { return readText(p.string()); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  fs::path dir_;
};

// The value of a flat metrics.json key: nullopt for null; fails the test when absent.
std::optional<double> value(const std::string& json, const std::string& key) {
  const std::string pattern = "\"" + key + "\": ";
  const size_t at = json.find(pattern);
  if (at == std::string::npos) {
    ADD_FAILURE() << "metrics.json has no key " << key;
    return std::nullopt;
  }
  const std::string rest = json.substr(at + pattern.size());
  if (rest.rfind("null", 0) == 0) return std::nullopt;
  return std::stod(rest);
}

}  // namespace

TEST_F(EvalLog, ARecordedRunGivesTheKnownMetrics) {
  writeRun(path("run.lcmlog"));
  const Result r = eval("--log " + path("run.lcmlog") + " --out " + path("out"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("eval: slot ATE 0.000 m"), std::string::npos) << r.out;
  const std::string json = slurp(dir_ / "out" / "metrics.json");
  EXPECT_NE(json.find("\"ego.source\": \"slot\""), std::string::npos) << json;
  // The backend is exact; odometry drifts.
  EXPECT_NEAR(*value(json, "ego.ate_rmse_m"), 0.0, 1e-6);
  EXPECT_NEAR(*value(json, "ego.rpe1_t_m"), 0.0, 1e-6);
  EXPECT_NEAR(*value(json, "ego.rpe10_t_m"), 0.0, 1e-6);
  EXPECT_NEAR(*value(json, "ego.t_rel_short_pct"), 0.0, 1e-6);
  EXPECT_FALSE(value(json, "ego.t_rel_pct"));  // a 30 m drive has no 100 m segment
  EXPECT_FALSE(value(json, "ego.r_rel_deg_per_100m"));
  EXPECT_NEAR(*value(json, "sources.slot.ate_rmse_m"), 0.0, 1e-6);
  EXPECT_GT(*value(json, "sources.odometry.ate_rmse_m"), 0.001);
  EXPECT_NEAR(*value(json, "sources.odometry.rpe1_t_m"), 0.01, 1e-3);
  // Tracking: exact tracks (the stale one is not output, the DontCare region is empty).
  EXPECT_DOUBLE_EQ(*value(json, "tracking.mota"), 1.0);
  EXPECT_NEAR(*value(json, "tracking.motp_m"), 0.0, 1e-6);
  EXPECT_EQ(*value(json, "tracking.idsw"), 0);
  EXPECT_EQ(*value(json, "tracking.fp"), 0);
  EXPECT_EQ(*value(json, "tracking.fn"), 0);
  EXPECT_NEAR(*value(json, "tracking.hota"), 1.0, 1e-9);
  EXPECT_NEAR(*value(json, "tracking.velocity_rmse_mps"), 0.0, 1e-6);
  EXPECT_NEAR(*value(json, "tracking.velocity_young_rmse_mps"), *value(json, "velocity.age.0-4.rmse_mps"), 1e-12);
  // The moving track's velocity covariance (sigma 0.2 m/s) holds its exact velocity.
  EXPECT_NEAR(*value(json, "tracking.velocity_nees"), 0.0, 1e-6);
  EXPECT_DOUBLE_EQ(*value(json, "tracking.velocity_within_95"), 1.0);
  EXPECT_DOUBLE_EQ(*value(json, "tracking.velocity_young_within_95"), 1.0);
  // The backend's registrations by outcome, from its last status; its other counters are not these.
  EXPECT_EQ(*value(json, "registration.measured"), 7);
  EXPECT_EQ(*value(json, "registration.too_few_points"), 3);
  EXPECT_EQ(json.find("registration.landmarks"), std::string::npos);
  EXPECT_DOUBLE_EQ(*value(json, "tracking_iou.mota"), 1.0);
  EXPECT_NEAR(*value(json, "tracking_iou.hota"), 1.0, 1e-9);
  // Timing: odometry totals 10, 11, 12, ... (mean 11, p95 12); stages get their own key.
  EXPECT_NEAR(*value(json, "timing_ms.odometry.mean"), 11.0, 1e-9);
  EXPECT_NEAR(*value(json, "timing_ms.odometry.p95"), 12.0, 1e-9);
  EXPECT_NEAR(*value(json, "timing_ms.odometry.features.mean"), 2.0, 1e-9);
  EXPECT_NEAR(*value(json, "timing_ms.tracker.mean"), 1.0, 1e-9);
  EXPECT_NEAR(*value(json, "timing_ms.backend.mean"), 5.0, 1e-9);
  EXPECT_NEAR(*value(json, "timing_ms.backend.solve.p95"), 4.0, 1e-9);
  for (const char* channel : {"LIDAR_SCAN", "GROUND_TRUTH", "ODOMETRY", "ASSOCIATIONS", "SLOT_STATE"})
    EXPECT_EQ(*value(json, std::string("frames.") + channel), kFrames) << channel;
  EXPECT_EQ(*value(json, "frames.DETECTIONS"), 0);
  EXPECT_TRUE(fs::exists(dir_ / "out" / "plots" / "trajectories.png"));
  EXPECT_TRUE(fs::exists(dir_ / "out" / "plots" / "error_over_distance.png"));
  EXPECT_TRUE(fs::exists(dir_ / "out" / "plots" / "velocity_error_by_range.png"));
  EXPECT_TRUE(fs::exists(dir_ / "out" / "plots" / "velocity_error_by_age.png"));
  const std::string report = slurp(dir_ / "out" / "report.md");
  EXPECT_NE(report.find("| slot (primary)"), std::string::npos) << report;
  EXPECT_NE(report.find("process odometry: 30 frames"), std::string::npos) << report;
  EXPECT_NE(report.find("Velocity covariances: 100.0 % of"), std::string::npos) << report;
  // The backend's test of the odometry, counted from SLOT_STATE and said on the summary line.
  EXPECT_EQ(*value(json, "ego.odometry_tested_frames"), kFrames - 1);
  EXPECT_EQ(*value(json, "ego.odometry_disagreement_frames"), 2);
  EXPECT_EQ(*value(json, "ego.odometry_downweighted_frames"), 2);
  EXPECT_NEAR(*value(json, "ego.odometry_max_disagreement_m"), 2.1, 1e-9);
  EXPECT_NE(r.out.find("contradicted the odometry on 2 scans"), std::string::npos) << r.out;
  EXPECT_NE(report.find("frames 10 11."), std::string::npos) << report;
}

TEST_F(EvalLog, ExportedFilesEvaluateLikeTheLog) {
  writeRun(path("run.lcmlog"));
  writeKittiLayout(dir_ / "kitti");
  const std::string kitti = " --kitti " + path("kitti") + " --sequence 0000";
  // Ground truth from the data set's files instead of the log: same answers.
  Result r = eval("--log " + path("run.lcmlog") + kitti + " --out " + path("out") + " --export " + path("export"));
  ASSERT_EQ(r.code, 0) << r.err;
  std::string json = slurp(dir_ / "out" / "metrics.json");
  EXPECT_NEAR(*value(json, "ego.ate_rmse_m"), 0.0, 1e-6);
  EXPECT_DOUBLE_EQ(*value(json, "tracking.mota"), 1.0);
  EXPECT_NEAR(*value(json, "tracking.hota"), 1.0, 1e-6);
  for (const char* f : {"trajectory_slot_kitti.txt", "trajectory_slot_tum.txt", "trajectory_slot_kitti_cam.txt",
                        "trajectory_odometry_kitti.txt", "tracks_kitti.txt"})
    EXPECT_TRUE(fs::exists(dir_ / "export" / f)) << f;
  const eval::Trajectory slot = eval::readTrajectory(path("export/trajectory_slot_kitti.txt"), eval::TrajectoryFormat::Kitti);
  ASSERT_EQ(slot.size(), static_cast<size_t>(kFrames));
  for (int t = 0; t < kFrames; ++t) EXPECT_TRUE(slot.poses[t].isApprox(truePose(t), 1e-9)) << t;
  // Tracks read back from the KITTI format sit on the labels (stale track excluded).
  const auto tracks = eval::readKittiTracks(path("export/tracks_kitti.txt"), testCalib(), kFrames);
  ASSERT_EQ(tracks[7].boxes.size(), 2u);
  const Box expected = worldObjects(7)[0].transformed(truePose(7).inverse());
  EXPECT_NEAR((tracks[7].boxes[0].center - expected.center).norm(), 0.0, 1e-5);
  EXPECT_NEAR(wrapAngle(tracks[7].boxes[0].yaw - expected.yaw), 0.0, 1e-5);

  // Only boxes in the camera image are written: the pedestrian the ego has passed is left out.
  int in_image = 0;
  for (int t = 0; t < kFrames; ++t)
    for (const Box& b : worldObjects(t))
      in_image += kitti::resultRow(t, b.transformed(truePose(t).inverse()), testCalib()).has_value();
  ASSERT_GT(in_image, 0);
  ASSERT_LT(in_image, 2 * kFrames);
  EXPECT_NE(r.err.find("tracks_kitti.txt: " + std::to_string(in_image) + " rows; " + std::to_string(2 * kFrames - in_image) +
                       " track boxes outside the camera image left out"),
            std::string::npos)
      << r.err;
  const std::string log_json = json;

  // The exported files evaluated as result files.
  r = eval("--traj " + path("export/trajectory_slot_kitti_cam.txt") + " --traj-format kitti_cam --tracks " +
           path("export/tracks_kitti.txt") + kitti + " --out " + path("files"));
  ASSERT_EQ(r.code, 0) << r.err;
  json = slurp(dir_ / "files" / "metrics.json");
  EXPECT_NE(json.find("\"ego.source\": \"result\""), std::string::npos) << json;
  EXPECT_NEAR(*value(json, "ego.ate_rmse_m"), 0.0, 1e-6);
  // Bird's-eye view (360 deg): the labels outside the image are missed, nothing else.
  EXPECT_DOUBLE_EQ(*value(json, "tracking.fn"), 2 * kFrames - in_image);
  EXPECT_DOUBLE_EQ(*value(json, "tracking.fp"), 0);
  EXPECT_DOUBLE_EQ(*value(json, "tracking.idsw"), 0);
  // The KITTI protocol scores the log's tracks (projected, outside the image not scored) and the
  // exported file alike.
  for (const char* cls : {"car", "pedestrian"})
    for (const char* key : {"mota", "motp", "samota", "amota", "idsw", "frag", "tp", "fp", "fn", "labels", "hota"}) {
      const std::string k = std::string("tracking.") + cls + "." + key;
      const std::optional<double> a = value(log_json, k), b = value(json, k);
      ASSERT_EQ(a.has_value(), b.has_value()) << k;
      if (a) {  // the file holds 6 decimals
        EXPECT_NEAR(*a, *b, 1e-4) << k;
      }
    }
  EXPECT_DOUBLE_EQ(*value(json, "tracking.car.tp") + *value(json, "tracking.pedestrian.tp"), in_image);
  // Track velocities come from the tracks' positions and the system's poses: exact here.
  EXPECT_NEAR(*value(json, "tracking.velocity_rmse_mps"), 0.0, 1e-4);
  EXPECT_EQ(json.find("timing_ms."), std::string::npos);  // result files carry no timing
}

TEST_F(EvalLog, ResultsWithoutTwoDimensionalBoxesAreFlaggedAndFlatterTheTracker) {
  writeKittiLayout(dir_ / "kitti");
  const std::string kitti = " --kitti " + path("kitti") + " --sequence 0000";
  // The labelled car, plus a false car track 10 m ahead of it, in every frame: once with the 2-D
  // box of a projected 3-D box, once with 0 0 0 0 (as the tracker wrote before).
  std::vector<kitti::LabelRow> good, flat;
  for (int t = 0; t < kFrames; ++t) {
    Box car = worldObjects(t)[0].transformed(truePose(t).inverse());
    car.id = 1;
    Box ghost = car;
    ghost.center.x() += 10;
    ghost.id = 2;
    for (const Box& b : {car, ghost})
      if (const auto row = kitti::resultRow(t, b, testCalib())) {
        good.push_back(*row);
        flat.push_back(*row);
        flat.back().bbox2d.setZero();
      }
  }
  ASSERT_GT(good.size(), 30u);
  kitti::writeTrackingLabels(path("good.txt"), good);
  kitti::writeTrackingLabels(path("flat.txt"), flat);
  Result r = eval("--tracks " + path("good.txt") + kitti + " --out " + path("good"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err.find("no 2-D box"), std::string::npos) << r.err;
  const std::string json = slurp(dir_ / "good" / "metrics.json");
  const int ghosts = static_cast<int>(good.size()) - static_cast<int>(*value(json, "tracking.car.tp"));
  EXPECT_GT(ghosts, 0);
  EXPECT_DOUBLE_EQ(*value(json, "tracking.car.fp"), ghosts);
  r = eval("--tracks " + path("flat.txt") + kitti + " --out " + path("flat"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("warning: KITTI protocol: " + std::to_string(flat.size()) + " of " +
                       std::to_string(flat.size()) + " rows"),
            std::string::npos)
      << r.err;
  // As the devkit counts it: no 2-D box, no false positive.
  EXPECT_DOUBLE_EQ(*value(slurp(dir_ / "flat" / "metrics.json"), "tracking.car.fp"), 0);
}

TEST_F(EvalLog, ALogWithoutGroundTruthIsAnErrorUnlessAllowed) {
  writeRun(path("run.lcmlog"), false);
  Result r = eval("--log " + path("run.lcmlog"));
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("no ground truth"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(path("run.lcmlog")), std::string::npos) << r.err;
  r = eval("--log " + path("run.lcmlog") + " --allow-missing-truth --out " + path("out"));
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string json = slurp(dir_ / "out" / "metrics.json");
  EXPECT_FALSE(value(json, "ego.ate_rmse_m"));
  EXPECT_FALSE(value(json, "sources.odometry.ate_rmse_m"));
  EXPECT_FALSE(value(json, "tracking.mota"));
  EXPECT_NEAR(*value(json, "timing_ms.odometry.mean"), 11.0, 1e-9);
}

TEST_F(EvalLog, TruncatedCorruptEmptyAndMissingLogsAreClearErrors) {
  writeRun(path("run.lcmlog"));
  const auto size = fs::file_size(path("run.lcmlog"));
  fs::copy_file(path("run.lcmlog"), path("truncated.lcmlog"));
  fs::resize_file(path("truncated.lcmlog"), size - 7);
  Result r = eval("--log " + path("truncated.lcmlog"));
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find(path("truncated.lcmlog") + ": truncated or corrupt log"), std::string::npos) << r.err;

  // Garbage between two events (LCM 1.3 stops there, later versions skip it silently).
  {
    lcm::LogFile log(path("garbage.lcmlog"), "w");
    ground_truth_t gt{};
    write(log, "GROUND_TRUTH", gt, 0);
    std::fwrite("garbage!", 1, 8, log.getFilePtr());
    write(log, "GROUND_TRUTH", gt, 1);
  }
  r = eval("--log " + path("garbage.lcmlog"));
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find(path("garbage.lcmlog") + ": "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("corrupt log"), std::string::npos) << r.err;

  // A header that claims more data than the file holds: refused before LCM allocates it (with
  // 0x7fffffff, LCM 1.3.1's size + 1 overflowed and dlslot-eval died of SIGSEGV; lcm_log.hpp).
  for (const uint32_t claimed : {0x7fffffffu, 0x40000000u}) {
    std::string bytes = slurp(path("run.lcmlog"));
    for (int k = 0; k < 4; ++k) bytes[24 + k] = static_cast<char>((claimed >> (24 - 8 * k)) & 0xff);
    std::ofstream(path("claims.lcmlog"), std::ios::binary) << bytes;
    r = eval("--log " + path("claims.lcmlog"));
    EXPECT_EQ(r.code, 1) << claimed;
    EXPECT_NE(r.err.find(path("claims.lcmlog") + ": truncated or corrupt log: the event at offset 0 claims"),
              std::string::npos) << r.err;
  }

  // A message that does not decode as the channel's type: skipped, counted and named
  // (one bad message must not make a recorded run unreadable); nothing else here, so no truth.
  {
    lcm::LogFile log(path("wrongtype.lcmlog"), "w");
    ground_truth_t gt{};
    write(log, "ODOMETRY", gt, 0);
  }
  r = eval("--log " + path("wrongtype.lcmlog"));
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find(path("wrongtype.lcmlog") + ": event 0: ODOMETRY: refused a message (fingerprint"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("1 events refused and skipped (ODOMETRY.fingerprint 1)"), std::string::npos) << r.err;

  std::ofstream(path("empty.lcmlog")).close();
  r = eval("--log " + path("empty.lcmlog"));
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("no events"), std::string::npos) << r.err;

  r = eval("--log " + path("missing.lcmlog"));
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find(path("missing.lcmlog")), std::string::npos) << r.err;

  fs::create_directories(path("directory.lcmlog"));
  r = eval("--log " + path("directory.lcmlog"));
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find(path("directory.lcmlog") + ": is not a file"), std::string::npos) << r.err;
}

TEST_F(EvalLog, ResultFilesOfDifferentLengthsOrWithoutGroundTruthAreRejected) {
  std::vector<Pose> poses;
  for (int t = 0; t < kFrames; ++t) poses.push_back(truePose(t));
  kitti::writePoses(path("est.txt"), poses);
  poses.pop_back();
  kitti::writePoses(path("gt.txt"), poses);
  Result r = eval("--traj " + path("est.txt") + " --gt-poses " + path("gt.txt"));
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find(path("est.txt") + ": has 30 poses but the ground truth (" + path("gt.txt") + ") has 29"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("different lengths"), std::string::npos) << r.err;

  r = eval("--traj " + path("est.txt"));
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("no ground truth"), std::string::npos) << r.err;

  r = eval("--traj " + path("est.txt") + " --gt-poses " + path("nothere.txt"));
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find(path("nothere.txt")), std::string::npos) << r.err;

  r = eval("--traj " + path("est.txt") + " --gt-poses " + path("est.txt") + " --out " + path("ok"));
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NEAR(*value(slurp(dir_ / "ok" / "metrics.json"), "ego.ate_rmse_m"), 0.0, 1e-9);
}
