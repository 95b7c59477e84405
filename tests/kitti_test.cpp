// KITTI readers and writers: hand-written files, known answers, round trips and bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "dlslot/input_error.hpp"
#include "dlslot/kitti.hpp"

using namespace dlslot;
using namespace dlslot::kitti;
namespace fs = std::filesystem;

namespace {

std::string tmpFile(const std::string& name, const std::string& content) {
  const fs::path dir = fs::temp_directory_path() / "dlslot_kitti_test";
  fs::create_directories(dir);
  const std::string path = (dir / name).string();
  std::ofstream(path) << content;
  return path;
}

// Expects an InputError whose message contains every needle (file, line, what was expected).
template <class F>
void expectInputError(F f, const std::vector<std::string>& needles) {
  try {
    f();
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    for (const auto& n : needles) EXPECT_NE(std::string(e.what()).find(n), std::string::npos) << e.what();
  }
}

const char* kCalibTracking =
    "P0: 7.215377e+02 0 6.095593e+02 0 0 7.215377e+02 1.728540e+02 0 0 0 1 0\n"
    "P2: 7.215377e+02 0 6.095593e+02 4.485728e+01 0 7.215377e+02 1.728540e+02 2.163791e-01 0 0 1 2.745884e-03\n"
    "R_rect 1 0 0 0 1 0 0 0 1\n"
    "Tr_velo_cam 0 -1 0 0 0 0 -1 -0.08 1 0 0 -0.27\n"
    "Tr_imu_velo 1 0 0 -0.81 0 1 0 0.32 0 0 1 -0.80\n";

}  // namespace

TEST(KittiCalib, ReadsBothKeySpellingsWithAndWithoutColon) {
  const Calib a = readCalib(tmpFile("calib_a.txt", kCalibTracking));
  const Calib b = readCalib(tmpFile("calib_b.txt",
                                    "R0_rect: 1 0 0 0 1 0 0 0 1\n"
                                    "Tr_velo_to_cam: 0 -1 0 0 0 0 -1 -0.08 1 0 0 -0.27\n"
                                    "Tr_imu_to_velo: 1 0 0 -0.81 0 1 0 0.32 0 0 1 -0.80\n"));
  EXPECT_TRUE(a.T_cam_velo.isApprox(b.T_cam_velo));
  ASSERT_TRUE(a.T_velo_imu && b.T_velo_imu);
  EXPECT_NEAR(a.T_velo_imu->translation().x(), -0.81, 1e-12);
  EXPECT_NEAR(a.T_cam_velo.translation().z(), -0.27, 1e-12);
  EXPECT_NEAR(a.P[2](0, 3), 44.85728, 1e-9);
  // A velodyne point 10 m ahead is 10 m along the camera's optical axis (z).
  EXPECT_NEAR((a.T_rect_velo() * Eigen::Vector3d(10, 0, 0)).z(), 10 - 0.27, 1e-12);
}

TEST(KittiCalib, RoundTripsThroughWriter) {
  const Calib a = readCalib(tmpFile("calib_rt.txt", kCalibTracking));
  const std::string path = tmpFile("calib_rt_out.txt", "");
  writeCalib(path, a);
  const Calib b = readCalib(path);
  EXPECT_TRUE(a.T_cam_velo.isApprox(b.T_cam_velo, 1e-12));
  EXPECT_TRUE(a.T_velo_imu->isApprox(*b.T_velo_imu, 1e-12));
  EXPECT_TRUE(a.P[2].isApprox(b.P[2], 1e-12));
}

TEST(KittiCalib, MissingVeloToCamIsAnErrorNamingTheFile) {
  const std::string path = tmpFile("calib_bad.txt", "R_rect 1 0 0 0 1 0 0 0 1\n");
  expectInputError([&] { readCalib(path); }, {path, "velodyne-to-camera"});
  const std::string short_row = tmpFile("calib_short.txt", "Tr_velo_cam 1 2 3\n");
  expectInputError([&] { readCalib(short_row); }, {short_row + ":1", "expected 12 numbers"});
}

TEST(KittiBoxes, CameraLidarRoundTripAndKnownAnswer) {
  const Calib calib = readCalib(tmpFile("calib_box.txt", kCalibTracking));
  // With this calib, camera x = -velo y, camera y = -velo z - 0.08, camera z = velo x - 0.27.
  CameraBox cam;
  cam.h = 1.5;
  cam.w = 1.6;
  cam.l = 4.0;
  cam.bottom_center = Eigen::Vector3d(2.0, 1.62, 20.0);
  cam.rotation_y = 0.0;  // facing camera +x = velo -y
  const Box b = cameraToLidar(cam, calib);
  EXPECT_NEAR(b.center.x(), 20.27, 1e-9);
  EXPECT_NEAR(b.center.y(), -2.0, 1e-9);
  EXPECT_NEAR(b.center.z(), -1.7 + 0.75, 1e-9);  // bottom at velo z = -1.7, centre h/2 above
  EXPECT_NEAR(b.yaw, -M_PI / 2, 1e-12);
  EXPECT_TRUE(b.size.isApprox(Eigen::Vector3d(4.0, 1.6, 1.5)));
  const CameraBox back = lidarToCamera(b, calib);
  EXPECT_TRUE(back.bottom_center.isApprox(cam.bottom_center, 1e-12));
  EXPECT_NEAR(back.rotation_y, cam.rotation_y, 1e-12);
  EXPECT_NEAR(back.h, cam.h, 1e-12);
}

TEST(KittiVelodyne, RoundTripAndBadFiles) {
  PointCloud scan(4, 3);
  scan << 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12;
  const std::string path = tmpFile("scan.bin", "");
  writeVelodyne(path, scan);
  EXPECT_EQ(fs::file_size(path), 48u);
  EXPECT_TRUE(readVelodyne(path).isApprox(scan));

  const std::string odd = tmpFile("odd.bin", std::string(20, '\0'));
  expectInputError([&] { readVelodyne(odd); }, {odd, "not a multiple of 16"});
  // A 0-byte file is a scan cut off or never written, not a 0-point frame.
  const std::string empty = tmpFile("empty.bin", "");
  expectInputError([&] { readVelodyne(empty); }, {empty, "empty scan (0 bytes"});
  PointCloud bad = scan;
  bad(1, 2) = std::nanf("");
  const std::string nan_path = tmpFile("nan.bin", "");
  writeVelodyne(nan_path, bad);
  expectInputError([&] { readVelodyne(nan_path); }, {nan_path, "point 2", "NaN"});
  expectInputError([&] { readVelodyne("/nonexistent/x.bin"); }, {"/nonexistent/x.bin", "cannot open"});
}

TEST(KittiLabels, ParsesTrackingLabelsAndDetections) {
  const std::string path = tmpFile("labels.txt",
                                   "0 -1 DontCare -1 -1 -10 219.31 188.49 245.5 218.56 -1000 -1000 -1000 -10 -1 -1 -1\n"
                                   "0 0 Van 0 0 -1.79 296.7 161.7 455.2 292.4 2.0 1.82 4.43 -4.55 1.86 13.41 -2.12\n"
                                   "1 0 Van 0 0 -1.79 296.7 161.7 455.2 292.4 2.0 1.82 4.43 -4.55 1.86 13.41 -2.12 0.9\n");
  const auto rows = readTrackingLabels(path);
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[1].type, "Van");
  EXPECT_EQ(rows[1].track_id, 0);
  EXPECT_NEAR(rows[1].box.l, 4.43, 1e-12);
  EXPECT_FALSE(rows[1].score.has_value());
  EXPECT_NEAR(*rows[2].score, 0.9, 1e-12);
  const Calib calib = readCalib(tmpFile("calib_l.txt", kCalibTracking));
  const auto frames = boxesByFrame(rows, calib, 2);
  EXPECT_EQ(frames[0].boxes.size(), 1u);
  EXPECT_EQ(frames[0].dontcare.size(), 0u);  // real DontCare rows have no 3D box
  EXPECT_EQ(frames[1].boxes.size(), 1u);
  EXPECT_EQ(boxesByFrame(rows, calib, 2, 0.95)[1].boxes.size(), 0u);  // below the score threshold

  const std::string csv = tmpFile("det.csv", "0,2,298.3,165.1,458.2,293.4,8.29,1.96,1.81,4.75,-4.57,1.84,13.53,-2.11,-1.78\n"
                                             "3,1,1.0,1.0,2.0,2.0,-0.5,1.7,0.6,0.8,1.0,1.6,8.0,0.1,0.1\n");
  const auto det = readCsvDetections(csv);
  ASSERT_EQ(det.size(), 2u);
  EXPECT_EQ(det[0].type, "Car");
  EXPECT_EQ(det[1].type, "Pedestrian");
  EXPECT_NEAR(*det[1].score, -0.5, 1e-12);
  EXPECT_NEAR(det[0].box.bottom_center.z(), 13.53, 1e-12);
}

TEST(KittiLabels, BadLinesNameFileLineAndExpectation) {
  const std::string few = tmpFile("few.txt", "0 1 Car 0 0 0 1 2 3 4 1.5 1.6 4.0 1 2 3\n");
  expectInputError([&] { readTrackingLabels(few); }, {few + ":1", "expected 17 fields", "got 16"});
  const std::string nonnum = tmpFile("nonnum.txt",
                                     "0 1 Car 0 0 0 1 2 3 4 1.5 1.6 4.0 1 2 3 0\n0 1 Car 0 0 0 1 2 3 4 1.5 abc 4.0 1 2 3 0\n");
  expectInputError([&] { readTrackingLabels(nonnum); }, {nonnum + ":2", "w: expected a number", "'abc'"});
  const std::string csv = tmpFile("bad.csv", "0,2,1,2,3\n");
  expectInputError([&] { readCsvDetections(csv); }, {csv + ":1", "expected 15 comma-separated fields"});
  const std::string badtype = tmpFile("badtype.csv", "0,7,298.3,165.1,458.2,293.4,8.29,1.96,1.81,4.75,-4.57,1.84,13.53,-2.11,-1.78\n");
  expectInputError([&] { readCsvDetections(badtype); }, {badtype + ":1", "type"});
}

TEST(KittiOxts, KnownAnswerAndRoundTrip) {
  // Two records 1e-4 degrees of longitude apart at latitude 49: the second pose is the
  // Mercator distance cos(49 deg) * 1e-4 * pi * 6378137 / 180 = 7.303215703755 m east.
  OxtsRecord a{}, b{};
  a[0] = b[0] = 49.0;
  a[1] = 8.0;
  b[1] = 8.0001;
  a[2] = b[2] = 110.0;
  b[5] = M_PI / 2;  // and turned to face north
  const auto poses = oxtsToLidarPoses({a, b}, Pose::Identity());
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_TRUE(poses[0].isApprox(Pose::Identity()));
  EXPECT_NEAR(poses[1].translation().x(), 7.303215703755, 1e-6);
  EXPECT_NEAR(poses[1].translation().y(), 0.0, 1e-9);
  EXPECT_NEAR(yawOf(poses[1].linear()), M_PI / 2, 1e-12);

  // Simulator direction: poses -> oxts text -> poses within a micrometre.
  Pose T_velo_imu = Pose::Identity();
  T_velo_imu.translation() << -0.81, 0.32, -0.80;
  std::vector<Pose> truth;
  for (int i = 0; i < 50; ++i) {
    Pose T = Pose::Identity();
    T.linear() = (Eigen::AngleAxisd(0.02 * i, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitY()))
                     .toRotationMatrix();
    T.translation() << 1.3 * i, 0.02 * i * i, 0.01 * i;
    truth.push_back(T);
  }
  truth[0] = Pose::Identity();
  const std::string path = tmpFile("oxts.txt", "");
  writeOxts(path, lidarPosesToOxts(truth, T_velo_imu, 49.011, 8.423, 112.0));
  const auto back = oxtsToLidarPoses(readOxts(path), T_velo_imu);
  ASSERT_EQ(back.size(), truth.size());
  for (size_t i = 0; i < truth.size(); ++i) {
    EXPECT_LT((back[i].translation() - truth[i].translation()).norm(), 1e-6) << i;
    EXPECT_LT(Eigen::AngleAxisd(back[i].linear().transpose() * truth[i].linear()).angle(), 1e-9) << i;
  }
}

TEST(KittiOxts, WrongFieldCountIsAnError) {
  const std::string path = tmpFile("oxts_bad.txt", "49 8 110 0 0 0\n");
  expectInputError([&] { readOxts(path); }, {path + ":1", "expected 30 oxts fields", "got 6"});
}

TEST(KittiPoses, RoundTripAndBadLine) {
  Pose T = Pose::Identity();
  T.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  T.translation() << 1, -2, 3;
  const std::string path = tmpFile("poses.txt", "");
  writePoses(path, {Pose::Identity(), T});
  const auto back = readPoses(path);
  ASSERT_EQ(back.size(), 2u);
  EXPECT_TRUE(back[1].isApprox(T, 1e-12));
  const std::string bad = tmpFile("poses_bad.txt", "1 0 0 0 0 1 0 0 0 0 1\n");
  expectInputError([&] { readPoses(bad); }, {bad + ":1", "expected 12 numbers"});
}

TEST(KittiSequence, MissingFoldersAreClearErrors) {
  expectInputError([] { locateSequence("/nonexistent/kitti", "0000"); }, {"/nonexistent/kitti", "not a directory"});
  const fs::path root = fs::temp_directory_path() / "dlslot_kitti_test" / "empty_root";
  fs::create_directories(root);
  expectInputError([&] { locateSequence(root.string(), "0007"); }, {"no sequence '0007'", "velodyne"});
}

TEST(KittiClasses, CompatibilityAsTheDevkit) {
  EXPECT_TRUE(classesCompatible("Car", "Van"));
  EXPECT_TRUE(classesCompatible("Pedestrian", "Person_sitting"));
  EXPECT_FALSE(classesCompatible("Car", "Pedestrian"));
  EXPECT_FALSE(classesCompatible("Car", "Truck"));
}

// Real data: every labelled car, moved to the lidar frame, must contain scan points.
TEST(KittiRealData, LabelledCarsContainScanPoints) {
  const std::string root = std::string(DLSLOT_SOURCE_DIR) + "/../shared/data/kitti-tracking-0000-head";
  if (!fs::exists(root)) GTEST_SKIP() << "real data slice not present at " << root;
  SequenceReader reader(root, "0000");
  ASSERT_EQ(reader.size(), 30);
  int cars = 0;
  for (int i = 0; i < reader.size(); ++i) {
    const Frame f = reader.read(i);
    EXPECT_GT(f.scan.cols(), 100000);
    for (const Box& b : f.labels) {
      if (b.type != "Car" && b.type != "Van") continue;
      if (b.center.head<2>().norm() > 40) continue;  // far cars may legitimately have almost no points
      int inside = 0;
      for (Eigen::Index k = 0; k < f.scan.cols(); ++k) inside += b.contains(f.scan.col(k).head<3>().cast<double>());
      EXPECT_GT(inside, 10) << "frame " << i << " track " << b.id;
      ++cars;
    }
  }
  EXPECT_GT(cars, 20);
}

TEST(KittiSequence, DetectionOnlySequencesHaveFramesFromLabelsAndDetections) {
  // The MOT setting: labels, calib and detections, no velodyne/.
  const fs::path root = fs::temp_directory_path() / "dlslot_kitti_test" / "mot_root";
  fs::remove_all(root);
  fs::create_directories(root / "training" / "label_02");
  fs::create_directories(root / "training" / "calib");
  std::ofstream(root / "training" / "calib" / "0003.txt") << kCalibTracking;
  std::ofstream(root / "training" / "label_02" / "0003.txt")
      << "0 0 Car 0 0 -1.5 100 150 200 250 1.5 1.6 4.0 2.0 1.6 20.0 -1.57\n"
      << "4 0 Car 0 0 -1.5 100 150 200 250 1.5 1.6 4.0 2.0 1.6 19.0 -1.57\n";
  const std::string dets = tmpFile("mot_dets.txt", "0,2,100,150,200,250,5.0,1.5,1.6,4.0,2.0,1.6,20.0,-1.57,-1.5\n"
                                                   "6,2,100,150,200,250,3.0,1.5,1.6,4.0,2.0,1.6,18.0,-1.57,-1.5\n");
  const SequenceReader reader(root.string(), "0003", {dets});
  EXPECT_FALSE(reader.hasScans());
  EXPECT_EQ(reader.size(), 7);  // the detections reach frame 6
  const Frame f = reader.read(6);
  EXPECT_EQ(f.scan.cols(), 0);
  ASSERT_EQ(f.detections.size(), 1u);
  EXPECT_NEAR(f.detections[0].center.x(), 18.27, 1e-9);  // z_cam 18 + 0.27 (Tr_velo_cam)
  EXPECT_EQ(reader.read(4).labels.size(), 1u);
  // Without labels, detections or scans there is nothing to count frames from.
  fs::remove(root / "training" / "label_02" / "0003.txt");
  expectInputError([&] { SequenceReader(root.string(), "0003"); }, {"0003", "no scans", "no labels"});
}
