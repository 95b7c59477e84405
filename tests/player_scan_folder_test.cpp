// Your own recordings in: the sensor calibration YAML, the scan folder (times, ground truth
// through the extrinsics), PCD reading and the beam layout estimated from a scan.
#include <gtest/gtest.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "dlslot/input_error.hpp"
#include "dlslot/kitti.hpp"
#include "scan_folder.hpp"
#include "sim/sensor.hpp"

using namespace dlslot;
namespace fs = std::filesystem;

namespace {

constexpr double kDeg = M_PI / 180.0;

std::string scratch(const std::string& name) {
  const fs::path dir = fs::path(DLSLOT_BIN_DIR) / ".." / "test-scratch" / "player_scan_folder" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

void write(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

const char* kCalib = R"(sensor_to_vehicle:
  translation: [1.0, 0, 1.5]
  rotation_rpy_deg: [0, 0, 90]
beams:
  model: uniform
  count: 32
  elevation_deg: [10.67, -30.67]
range_m: [2, 50]
)";

std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

TEST(SensorCalibration, ReadsExtrinsicsBeamsAndRanges) {
  const std::string dir = scratch("calib");
  write(dir + "/calib.yaml", std::string(kCalib) + "camera_calib: cam/0000.txt\n");
  const auto c = player::readSensorCalibration(dir + "/calib.yaml");
  EXPECT_EQ(c.beam_model, "uniform");
  EXPECT_EQ(c.beams, 32);
  EXPECT_DOUBLE_EQ(c.top_elevation_deg, 10.67);
  EXPECT_DOUBLE_EQ(c.bottom_elevation_deg, -30.67);
  EXPECT_DOUBLE_EQ(c.min_range_m, 2);
  EXPECT_DOUBLE_EQ(c.max_range_m, 50);
  EXPECT_TRUE(c.T_vehicle_sensor.translation().isApprox(Eigen::Vector3d(1, 0, 1.5)));
  // Yaw 90 deg: the sensor's x axis is the vehicle's y axis.
  EXPECT_TRUE((c.T_vehicle_sensor.linear() * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY(), 1e-12));
  EXPECT_EQ(c.camera_calib, (fs::path(dir) / "cam/0000.txt").lexically_normal().string());
  // A sensor stores its points on their rays unless its calibration says how far below (KITTI's 0.22 deg).
  EXPECT_EQ(c.vertical_angle_error_deg, 0.0);
  write(dir + "/kitti.yaml", std::string(kCalib) + "vertical_angle_error_deg: 0.22\n");
  EXPECT_DOUBLE_EQ(player::readSensorCalibration(dir + "/kitti.yaml").vertical_angle_error_deg, 0.22);
}

TEST(SensorCalibration, BadFilesAreErrorsNamingTheFileAndTheKey) {
  const std::string dir = scratch("calib-bad");
  write(dir + "/a.yaml", "sensor_to_vehicle: {translation: [0, 0], rotation_rpy_deg: [0, 0, 0]}\nbeams: {model: estimate}\nrange_m: [0, 100]\n");
  std::string e = errorOf([&] { player::readSensorCalibration(dir + "/a.yaml"); });
  EXPECT_NE(e.find(dir + "/a.yaml"), std::string::npos) << e;
  EXPECT_NE(e.find("translation"), std::string::npos) << e;
  write(dir + "/b.yaml", "sensor_to_vehicle: {translation: [0, 0, 0], rotation_rpy_deg: [0, 0, 0]}\nbeams: {model: lasers}\nrange_m: [0, 100]\n");
  e = errorOf([&] { player::readSensorCalibration(dir + "/b.yaml"); });
  EXPECT_NE(e.find("beams.model"), std::string::npos) << e;
  write(dir + "/c.yaml", std::string(kCalib) + "colour: red\n");
  e = errorOf([&] { player::readSensorCalibration(dir + "/c.yaml"); });
  EXPECT_NE(e.find("colour"), std::string::npos) << e;  // an unknown key is an error, not ignored
  write(dir + "/d.yaml", std::string(kCalib) + "vertical_angle_error_deg: 22\n");  // degrees, not hundredths
  e = errorOf([&] { player::readSensorCalibration(dir + "/d.yaml"); });
  EXPECT_NE(e.find("vertical_angle_error_deg"), std::string::npos) << e;
  e = errorOf([&] { player::readSensorCalibration(dir + "/missing.yaml"); });
  EXPECT_NE(e.find("missing.yaml"), std::string::npos) << e;
}

TEST(ScanFolder, TimesFromTimesTxtOrFileNamesAndTheSensorsTrajectoryFromTheVehicles) {
  const std::string dir = scratch("folder");
  write(dir + "/calib.yaml", kCalib);
  const auto calib = player::readSensorCalibration(dir + "/calib.yaml");
  PointCloud scan(4, 1);
  scan << 10, 0, 0, 0.5;
  for (int i = 0; i < 3; ++i) kitti::writeVelodyne(dir + "/00000" + std::to_string(i) + ".bin", scan);
  EXPECT_NE(errorOf([&] { player::openScanFolder(dir, calib); }).find("not a timestamp"), std::string::npos);
  write(dir + "/times.txt", "0.0\n0.1\n");
  EXPECT_NE(errorOf([&] { player::openScanFolder(dir, calib); }).find("2 times for 3 scans"), std::string::npos);
  write(dir + "/times.txt", "0.0\n0.1\n0.2\n");
  // The vehicle drives 1 m a frame along its x; the sensor is turned 90 deg on it, so in the
  // first scan's sensor frame it moves along -y.
  std::vector<Pose> vehicle(3, Pose::Identity());
  for (int i = 0; i < 3; ++i) vehicle[i].translation() << 5 + i, 2, 0;
  kitti::writePoses(dir + "/poses.txt", vehicle);
  const auto f = player::openScanFolder(dir, calib);
  ASSERT_EQ(f.files.size(), 3u);
  EXPECT_DOUBLE_EQ(f.times[2], 0.2);
  ASSERT_EQ(f.gt_poses.size(), 3u);
  EXPECT_TRUE(f.gt_poses[0].isApprox(Pose::Identity()));
  EXPECT_TRUE(f.gt_poses[2].translation().isApprox(Eigen::Vector3d(0, -2, 0), 1e-9)) << f.gt_poses[2].translation().transpose();

  const std::string stamped = scratch("stamped");
  for (const char* name : {"1650000000200000.bin", "1650000000100000.bin"})
    kitti::writeVelodyne(stamped + "/" + name, scan);
  const auto s = player::openScanFolder(stamped, calib);
  ASSERT_EQ(s.files.size(), 2u);
  EXPECT_NEAR(s.times[1] - s.times[0], 0.1, 1e-6);
  EXPECT_EQ(fs::path(s.files[0]).filename(), "1650000000100000.bin");
}

TEST(ScanFolder, PcdScansWithAndWithoutIntensityAndRangeLimits) {
  const std::string dir = scratch("pcd");
  pcl::PointCloud<pcl::PointXYZI> a;
  a.push_back({1.0f, 0.0f, 0.0f, 0.7f});    // too near (range 1 < 2)
  a.push_back({10.0f, 0.0f, 1.0f, 0.3f});
  a.push_back({60.0f, 0.0f, 1.0f, 0.3f});   // too far (> 50)
  pcl::PointXYZI nan;
  nan.x = nan.y = nan.z = std::numeric_limits<float>::quiet_NaN();
  a.push_back(nan);
  pcl::io::savePCDFileBinary(dir + "/a.pcd", a);
  pcl::PointCloud<pcl::PointXYZ> b;
  b.push_back({3.0f, 4.0f, 5.0f});
  pcl::io::savePCDFileASCII(dir + "/b.pcd", b);
  const PointCloud pa = player::readScanFile(dir + "/a.pcd");
  ASSERT_EQ(pa.cols(), 4);
  EXPECT_FLOAT_EQ(pa(3, 1), 0.3f);
  const PointCloud pb = player::readScanFile(dir + "/b.pcd");
  ASSERT_EQ(pb.cols(), 1);
  EXPECT_FLOAT_EQ(pb(1, 0), 4.0f);
  EXPECT_FLOAT_EQ(pb(3, 0), 0.0f);
  write(dir + "/calib.yaml", kCalib);
  const PointCloud kept = player::limitRange(pa, player::readSensorCalibration(dir + "/calib.yaml"));
  ASSERT_EQ(kept.cols(), 1);
  EXPECT_FLOAT_EQ(kept(0, 0), 10.0f);
  write(dir + "/bad.pcd", "not a pcd");
  EXPECT_NE(errorOf([&] { player::readScanFile(dir + "/bad.pcd"); }).find("bad.pcd"), std::string::npos);
}

// A spinning lidar's scan: every beam's ring hits walls at ranges 5..40 m.
PointCloud ringScan(const std::vector<double>& elevations_deg) {
  std::vector<Eigen::Vector4f> pts;
  for (double el : elevations_deg)
    for (int a = 0; a < 1000; ++a) {
      const double az = 2 * M_PI * a / 1000, r = 5 + 35 * ((a * 7919) % 1000) / 1000.0;
      pts.emplace_back(r * std::cos(az), r * std::sin(az), r * std::tan(el * kDeg), 0.5f);
    }
  PointCloud out(4, static_cast<Eigen::Index>(pts.size()));
  for (size_t i = 0; i < pts.size(); ++i) out.col(i) = pts[i];
  return out;
}

TEST(EstimateBeams, FindsTheRingsOfEvenAndUnevenLayouts) {
  std::vector<double> even;
  for (int b = 0; b < 32; ++b) even.push_back(10.67 - b * (41.34 / 31));
  const auto e = player::estimateBeams(ringScan(even));
  EXPECT_EQ(e.beams, 32);
  EXPECT_NEAR(e.top_elevation_deg, 10.67, 0.05);
  EXPECT_NEAR(e.bottom_elevation_deg, -30.67, 0.05);
  EXPECT_TRUE(e.uniform);
  std::vector<double> hdl64;
  for (int b = 0; b < 64; ++b) hdl64.push_back(sim::beamElevationDeg(b));
  const auto h = player::estimateBeams(ringScan(hdl64));
  EXPECT_EQ(h.beams, 64);
  EXPECT_NEAR(h.top_elevation_deg, 2.0, 0.05);
  EXPECT_NEAR(h.bottom_elevation_deg, -24.33, 0.05);
  EXPECT_FALSE(h.uniform);  // 1/3 deg above, 1/2 deg below
}

}  // namespace
