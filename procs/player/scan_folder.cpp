#include "scan_folder.hpp"

#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>

#include "dlslot/config.hpp"
#include "dlslot/input_error.hpp"

namespace fs = std::filesystem;

namespace dlslot::player {

namespace {

constexpr double kDeg = M_PI / 180.0;

std::vector<double> numbers(ConfigSection& s, const std::string& key, size_t n) {
  std::vector<double> v;
  s.get(key, v);
  if (v.size() != n)
    throw InputError(s.file(), 0, s.path() + key + ": expected " + std::to_string(n) + " numbers, got " +
                                      std::to_string(v.size()));
  for (double x : v)
    if (!std::isfinite(x)) throw InputError(s.file(), 0, s.path() + key + ": expected finite numbers");
  return v;
}

// A file stem read as a timestamp in seconds, or nothing when it is not one.
std::optional<double> stemTime(const std::string& stem) {
  if (stem.empty() || stem.find_first_not_of("0123456789.") != std::string::npos) return std::nullopt;
  if (stem.find('.') != std::string::npos) {
    if (stem.find('.') < 9) return std::nullopt;  // 12.5 is no epoch time
    return std::stod(stem);
  }
  // Integers: the digit count says the unit (epoch times since 2001 have 10 digits of seconds).
  switch (stem.size()) {
    case 13: return std::stod(stem) * 1e-3;
    case 16: return std::stod(stem) * 1e-6;
    case 19: return std::stod(stem.substr(0, 10)) + std::stod(stem.substr(10)) * 1e-9;
    default: return std::nullopt;
  }
}

}  // namespace

SensorCalibration readSensorCalibration(const std::string& path) {
  SensorCalibration c;
  c.path = path;
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw InputError(path, 0, "cannot open (expected a YAML sensor calibration)");
  } catch (const YAML::Exception& e) {
    throw InputError(path, e.mark.line + 1, std::string("not YAML: ") + e.msg);
  }
  try {
    ConfigSection s(root, path, "");
    ConfigSection ext = s.section("sensor_to_vehicle");
    const auto t = numbers(ext, "translation", 3), rpy = numbers(ext, "rotation_rpy_deg", 3);
    ext.finish();
    c.T_vehicle_sensor.setIdentity();
    c.T_vehicle_sensor.linear() = (Eigen::AngleAxisd(rpy[2] * kDeg, Eigen::Vector3d::UnitZ()) *
                                   Eigen::AngleAxisd(rpy[1] * kDeg, Eigen::Vector3d::UnitY()) *
                                   Eigen::AngleAxisd(rpy[0] * kDeg, Eigen::Vector3d::UnitX()))
                                      .toRotationMatrix();
    c.T_vehicle_sensor.translation() << t[0], t[1], t[2];
    ConfigSection beams = s.section("beams");
    beams.get("model", c.beam_model);
    if (c.beam_model == "uniform") {
      beams.get("count", c.beams);
      if (c.beams < 2 || c.beams > 255)
        throw InputError(path, 0, "beams.count: expected 2..255, got " + std::to_string(c.beams));
      const auto el = numbers(beams, "elevation_deg", 2);
      c.top_elevation_deg = el[0], c.bottom_elevation_deg = el[1];
      if (!(el[0] > el[1]))
        throw InputError(path, 0, "beams.elevation_deg: expected [top, bottom] with top > bottom");
    } else if (c.beam_model == "hdl64") {
      c.beams = 64;
    } else if (c.beam_model != "estimate") {
      throw InputError(path, 0, "beams.model: expected estimate, uniform or hdl64, got '" + c.beam_model + "'");
    }
    beams.finish();
    const auto range = numbers(s, "range_m", 2);
    c.min_range_m = range[0], c.max_range_m = range[1];
    if (!(range[0] >= 0 && range[1] > range[0]))
      throw InputError(path, 0, "range_m: expected [min, max] with 0 <= min < max");
    if (s.has("vertical_angle_error_deg")) s.get("vertical_angle_error_deg", c.vertical_angle_error_deg);
    if (!(std::abs(c.vertical_angle_error_deg) <= 5.0))
      throw InputError(path, 0, "vertical_angle_error_deg: expected a value in [-5, 5] deg, got " +
                                    std::to_string(c.vertical_angle_error_deg));
    if (s.has("camera_calib")) {
      s.get("camera_calib", c.camera_calib);
      fs::path p(c.camera_calib);
      if (p.is_relative()) p = fs::path(path).parent_path() / p;
      c.camera_calib = p.lexically_normal().string();
    }
    s.finish();
  } catch (const ConfigError& e) {
    throw InputError(path, 0, e.what());
  }
  return c;
}

ScanFolder openScanFolder(const std::string& dir, const SensorCalibration& calib) {
  ScanFolder f;
  f.dir = dir;
  if (!fs::is_directory(dir)) throw InputError(dir, 0, "is not a directory (expected a folder of .pcd or .bin scans)");
  std::map<std::string, std::vector<std::string>> by_ext;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.is_regular_file() && (e.path().extension() == ".pcd" || e.path().extension() == ".bin"))
      by_ext[e.path().extension().string()].push_back(e.path().string());
  if (by_ext.empty()) throw InputError(dir, 0, "holds no .pcd or .bin scans");
  if (by_ext.size() > 1) throw InputError(dir, 0, "holds both .pcd and .bin files: expected scans of one kind");
  f.files = by_ext.begin()->second;
  std::sort(f.files.begin(), f.files.end());
  const fs::path times = fs::path(dir) / "times.txt";
  if (fs::exists(times)) {
    f.times = kitti::readTimes(times.string());
    if (f.times.size() != f.files.size())
      throw InputError(times.string(), 0, "has " + std::to_string(f.times.size()) + " times for " +
                                              std::to_string(f.files.size()) + " scans: expected one per scan");
  } else {
    std::vector<std::pair<double, std::string>> stamped;
    for (const auto& file : f.files) {
      const auto t = stemTime(fs::path(file).stem().string());
      if (!t)
        throw InputError(file, 0, "no times.txt in " + dir + " and this file name is not a timestamp (seconds "
                                  "with a decimal point, or 13/16/19 digits of ms/us/ns)");
      stamped.emplace_back(*t, file);
    }
    std::sort(stamped.begin(), stamped.end());
    f.files.clear();
    for (const auto& [t, file] : stamped) {
      f.times.push_back(t);
      f.files.push_back(file);
    }
  }
  for (size_t i = 1; i < f.times.size(); ++i)
    if (!(f.times[i] > f.times[i - 1]))
      throw InputError(fs::exists(times) ? times.string() : f.files[i], fs::exists(times) ? static_cast<int>(i) + 1 : 0,
                       "times must increase (scan " + std::to_string(i) + ")");
  const fs::path poses = fs::path(dir) / "poses.txt";
  if (fs::exists(poses)) {
    std::vector<Pose> vehicle = kitti::readPoses(poses.string());
    if (vehicle.size() != f.files.size())
      throw InputError(poses.string(), 0, "has " + std::to_string(vehicle.size()) + " poses for " +
                                              std::to_string(f.files.size()) + " scans: expected one per scan");
    // The sensor's trajectory, re-based so the world is the first scan's sensor frame.
    const Pose& E = calib.T_vehicle_sensor;
    const Pose first = (vehicle[0] * E).inverse();
    for (const Pose& T : vehicle) f.gt_poses.push_back(first * T * E);
  }
  return f;
}

PointCloud readScanFile(const std::string& path) {
  if (fs::path(path).extension() == ".bin") return kitti::readVelodyne(path);
  pcl::PCLPointCloud2 blob;
  pcl::PCDReader reader;
  // The header first: PCL's reader dereferences garbage past a header that declares no points or
  // fields (a text file named .pcd crashed it), so those are refused here.
  {
    Eigen::Vector4f origin;
    Eigen::Quaternionf orientation;
    int version = 0, data_type = 0;
    unsigned int data_idx = 0;
    if (reader.readHeader(path, blob, origin, orientation, version, data_type, data_idx) != 0)
      throw InputError(path, 0, "cannot read as PCD (no valid header)");
    if (blob.fields.empty() || static_cast<uint64_t>(blob.width) * blob.height == 0)
      throw InputError(path, 0, "the PCD header declares no fields or no points");
  }
  if (reader.read(path, blob) != 0) throw InputError(path, 0, "cannot read as PCD");
  bool has_intensity = false, has_xyz = 0;
  int xyz = 0;
  for (const auto& field : blob.fields) {
    has_intensity |= field.name == "intensity";
    xyz += field.name == "x" || field.name == "y" || field.name == "z";
  }
  has_xyz = xyz == 3;
  if (!has_xyz) throw InputError(path, 0, "has no x, y and z fields (expected a point cloud)");
  PointCloud out;
  if (has_intensity) {
    pcl::PointCloud<pcl::PointXYZI> cloud;
    pcl::fromPCLPointCloud2(blob, cloud);
    out.resize(4, static_cast<Eigen::Index>(cloud.size()));
    for (size_t i = 0; i < cloud.size(); ++i) out.col(i) << cloud[i].x, cloud[i].y, cloud[i].z, cloud[i].intensity;
  } else {
    pcl::PointCloud<pcl::PointXYZ> cloud;
    pcl::fromPCLPointCloud2(blob, cloud);
    out.resize(4, static_cast<Eigen::Index>(cloud.size()));
    for (size_t i = 0; i < cloud.size(); ++i) out.col(i) << cloud[i].x, cloud[i].y, cloud[i].z, 0.0f;
  }
  return out;
}

PointCloud limitRange(const PointCloud& scan, const SensorCalibration& calib) {
  PointCloud out(4, scan.cols());
  Eigen::Index n = 0;
  const double lo2 = calib.min_range_m * calib.min_range_m, hi2 = calib.max_range_m * calib.max_range_m;
  for (Eigen::Index i = 0; i < scan.cols(); ++i) {
    if (!scan.col(i).allFinite()) continue;
    const double r2 = double(scan(0, i)) * scan(0, i) + double(scan(1, i)) * scan(1, i);
    if (r2 < lo2 || r2 > hi2) continue;
    out.col(n++) = scan.col(i);
  }
  out.conservativeResize(4, n);
  return out;
}

BeamLayout estimateBeams(const PointCloud& scan) {
  constexpr double kBin = 0.05, kLo = -60, kHi = 60;
  const int bins = static_cast<int>((kHi - kLo) / kBin);
  std::vector<double> h(bins, 0.0), sum(bins, 0.0);  // points and their summed elevations per bin
  int used = 0;
  for (Eigen::Index i = 0; i < scan.cols(); ++i) {
    const double r = std::hypot(double(scan(0, i)), double(scan(1, i)));
    if (!(r > 1.0) || !std::isfinite(scan(2, i))) continue;  // the elevation of very near points is noisy
    const double el = std::atan2(double(scan(2, i)), r) / kDeg;
    const int b = static_cast<int>((el - kLo) / kBin);
    if (b < 0 || b >= bins) continue;
    h[b] += 1;
    sum[b] += el;
    ++used;
  }
  std::vector<double> s(bins, 0.0);
  for (int b = 1; b + 1 < bins; ++b) s[b] = h[b - 1] + h[b] + h[b + 1];
  // Peaks: local maxima (first of a flat top) holding a 2000th of the points: a beam of a
  // 128-beam sensor holds 1/128 of them, a top beam looking mostly at the sky still a tenth of that.
  const double min_peak = used / 2000.0;
  std::vector<double> peaks;  // degrees, from the bottom
  for (int b = 1; b + 1 < bins; ++b)
    if (s[b] >= min_peak && s[b] > s[b - 1] && s[b] >= s[b + 1]) {
      // The beam's angle: the mean elevation of the points within two bins of the peak.
      double n = 0, e = 0;
      for (int k = std::max(0, b - 2); k <= std::min(bins - 1, b + 2); ++k) n += h[k], e += sum[k];
      peaks.push_back(e / n);
    }
  BeamLayout out;
  out.beams = static_cast<int>(peaks.size());
  if (peaks.empty()) return out;
  out.top_elevation_deg = peaks.back();
  out.bottom_elevation_deg = peaks.front();
  if (peaks.size() >= 3) {
    // Evenly spaced: the angles lie on a line over the beam index, within a quarter of the gap
    // (RMS). Per-beam calibration scatter stays well inside it; the HDL-64E's two blocks (1/3
    // and 1/2 deg) leave over a gap.
    const double n = static_cast<double>(peaks.size());
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (size_t i = 0; i < peaks.size(); ++i) sx += i, sy += peaks[i], sxx += double(i) * i, sxy += i * peaks[i];
    const double slope = (n * sxy - sx * sy) / (n * sxx - sx * sx), icpt = (sy - slope * sx) / n;
    double ss = 0;
    for (size_t i = 0; i < peaks.size(); ++i) ss += std::pow(peaks[i] - (icpt + slope * i), 2);
    out.uniform = std::sqrt(ss / n) < 0.25 * std::abs(slope);
  } else {
    out.uniform = peaks.size() == 2;
  }
  return out;
}

FolderReader::FolderReader(const std::string& dir, const SensorCalibration& calib,
                           const std::vector<std::string>& detection_paths, double min_detection_score)
    : calib_(calib), folder_(openScanFolder(dir, calib)) {
  if (detection_paths.empty()) return;
  if (calib.camera_calib.empty())
    throw InputError(calib.path, 0, "detection files are in camera coordinates: name their KITTI calibration with "
                                    "camera_calib");
  const kitti::Calib cam = kitti::readCalib(calib.camera_calib);
  detections_.assign(size(), {});
  for (const std::string& path : detection_paths) {
    const auto frames = kitti::boxesByFrame(kitti::readDetectionRows(path), cam, size(), min_detection_score);
    for (int i = 0; i < size(); ++i)
      detections_[i].boxes.insert(detections_[i].boxes.end(), frames[i].boxes.begin(), frames[i].boxes.end());
  }
  for (auto& f : detections_)
    for (Box& b : f.boxes) b.id = -1;  // detector output carries no track ids
}

Frame FolderReader::read(int index) const {
  if (index < 0 || index >= size())
    throw std::out_of_range("frame " + std::to_string(index) + " outside 0.." + std::to_string(size() - 1));
  Frame f;
  f.index = index;
  f.utime = static_cast<int64_t>(std::llround(folder_.times[index] * 1e6));
  f.scan = limitRange(readScanFile(folder_.files[index]), calib_);
  if (!detections_.empty()) f.detections = detections_[index].boxes;
  if (!folder_.gt_poses.empty()) f.gt_pose = folder_.gt_poses[index];
  return f;
}

}  // namespace dlslot::player
