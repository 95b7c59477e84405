#include "dlslot/kitti.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>

#include "dlslot/input_error.hpp"
#include "dlslot/kitti_stream.hpp"

namespace fs = std::filesystem;

namespace dlslot::kitti {
namespace {

constexpr double kEarthRadius = 6378137.0;  // the KITTI devkit's Mercator radius
constexpr int kMaxFrame = 999999;      // six-digit file names (000000.bin)
constexpr int kMaxTrackId = 999999;    // far beyond any sequence; keeps ids exact in an int

std::vector<std::string> splitWs(const std::string& line) {
  std::istringstream is(line);
  std::vector<std::string> out;
  for (std::string t; is >> t;) out.push_back(t);
  return out;
}

std::vector<std::string> splitComma(const std::string& line) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : line) {
    if (c == ',') {
      out.push_back(cur);
      cur.clear();
    } else if (c != '\r' && c != ' ') {
      cur += c;
    }
  }
  out.push_back(cur);
  return out;
}

double number(const std::string& tok, const std::string& file, int line, const std::string& field) {
  size_t used = 0;
  double v = 0;
  try {
    v = std::stod(tok, &used);
  } catch (...) {
    used = 0;
  }
  if (used != tok.size() || tok.empty())
    throw InputError(file, line, field + ": expected a number, got '" + tok + "'");
  if (!std::isfinite(v)) throw InputError(file, line, field + ": expected a finite number, got '" + tok + "'");
  return v;
}

// An integer within [lo, hi] (the default: any int; a double beyond it must not wrap).
int integer(const std::string& tok, const std::string& file, int line, const std::string& field,
            double lo = std::numeric_limits<int>::min(), double hi = std::numeric_limits<int>::max()) {
  const double v = number(tok, file, line, field);
  if (v != std::floor(v)) throw InputError(file, line, field + ": expected an integer, got '" + tok + "'");
  if (v < lo || v > hi)
    throw InputError(file, line, field + ": expected an integer in " + std::to_string(static_cast<int64_t>(lo)) + ".." +
                                     std::to_string(static_cast<int64_t>(hi)) + ", got '" + tok + "'");
  return static_cast<int>(v);
}

// A path that exists and is a regular file (a directory opens as a stream on Linux and reads as
// garbage or fails with no file name).
void requireFile(const std::string& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw InputError(path, 0, "is a directory, expected a file");
}

std::ifstream openText(const std::string& path) {
  requireFile(path);
  std::ifstream in(path);
  if (!in) throw InputError(path, 0, "cannot open file");
  return in;
}

// Box sizes in metres: finite (number() saw to that) and positive.
void requirePositive(double v, const std::string& file, int line, const std::string& field) {
  if (!(v > 0)) throw InputError(file, line, field + ": expected a size > 0 m, got " + std::to_string(v));
}

Pose rowsToPose(const std::vector<double>& v) {  // 12 numbers, 3x4 row-major
  Pose T = Pose::Identity();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) T.matrix()(r, c) = v[r * 4 + c];
  return T;
}

void writeRows(std::FILE* f, const Eigen::MatrixXd& m) {
  for (int r = 0; r < m.rows(); ++r)
    for (int c = 0; c < m.cols(); ++c) std::fprintf(f, " %.12e", m(r, c));
}

std::FILE* openWrite(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) throw InputError(path, 0, "cannot open file for writing");
  return f;
}

// Closes a file opened by openWrite and throws if any of its writes failed: a full disk (or a
// file size limit) otherwise leaves empty or truncated files behind without a word.
void closeWrite(std::FILE* f, const std::string& path) {
  const bool failed = std::ferror(f) != 0;
  const int err = errno;
  if (std::fclose(f) != 0 || failed)
    throw InputError(path, 0, std::string("writing failed: ") + std::strerror(failed ? err : errno));
}

Eigen::Matrix3d rpyToR(double roll, double pitch, double yaw) {
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

}  // namespace

// ---------------- calib ----------------

Pose Calib::T_rect_velo() const {
  Pose R = Pose::Identity();
  R.linear() = R_rect;
  return R * T_cam_velo;
}

Calib readCalib(const std::string& path) {
  std::ifstream in = openText(path);
  return readCalib(in, path);
}

Calib readCalib(std::istream& in, const std::string& path) {
  Calib calib;
  bool have_velo_cam = false;
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    std::vector<std::string> tok = splitWs(line);
    if (tok.empty()) continue;
    std::string key = tok[0];
    if (!key.empty() && key.back() == ':') key.pop_back();
    std::vector<double> v;
    for (size_t i = 1; i < tok.size(); ++i) v.push_back(number(tok[i], path, n, key));
    auto need = [&](size_t count) {
      if (v.size() != count)
        throw InputError(path, n, key + ": expected " + std::to_string(count) + " numbers, got " +
                                      std::to_string(v.size()));
    };
    if (key == "R_rect" || key == "R0_rect") {
      need(9);
      for (int i = 0; i < 9; ++i) calib.R_rect(i / 3, i % 3) = v[i];
    } else if (key == "Tr_velo_cam" || key == "Tr_velo_to_cam" || key == "Tr") {
      need(12);
      calib.T_cam_velo = rowsToPose(v);
      have_velo_cam = true;
    } else if (key == "Tr_imu_velo" || key == "Tr_imu_to_velo") {
      need(12);
      calib.T_velo_imu = rowsToPose(v);
    } else if (key.size() == 2 && key[0] == 'P' && key[1] >= '0' && key[1] <= '3') {
      need(12);
      for (int i = 0; i < 12; ++i) calib.P[key[1] - '0'](i / 4, i % 4) = v[i];
    }
  }
  if (!have_velo_cam)
    throw InputError(path, 0, "no velodyne-to-camera transform (expected a Tr_velo_cam, Tr_velo_to_cam or Tr line)");
  return calib;
}

void writeCalib(const std::string& path, const Calib& calib) {
  std::FILE* f = openWrite(path);
  for (int i = 0; i < 4; ++i) {
    std::fprintf(f, "P%d", i);
    writeRows(f, calib.P[i]);
    std::fprintf(f, "\n");
  }
  std::fprintf(f, "R_rect");
  writeRows(f, calib.R_rect);
  std::fprintf(f, "\nTr_velo_cam");
  writeRows(f, calib.T_cam_velo.matrix().topRows<3>());
  std::fprintf(f, "\n");
  if (calib.T_velo_imu) {
    std::fprintf(f, "Tr_imu_velo");
    writeRows(f, calib.T_velo_imu->matrix().topRows<3>());
    std::fprintf(f, "\n");
  }
  closeWrite(f, path);
}

// ---------------- velodyne ----------------

PointCloud readVelodyne(const std::string& path) {
  requireFile(path);
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw InputError(path, 0, "cannot open velodyne scan");
  const std::streamsize bytes = in.tellg();
  std::vector<char> data(static_cast<size_t>(bytes));
  in.seekg(0);
  in.read(data.data(), bytes);
  if (!in) throw InputError(path, 0, "short read");
  return readVelodyne(data.data(), data.size(), path);
}

PointCloud readVelodyne(const char* data, size_t bytes, const std::string& path) {
  // A lidar sweep without a single return is a file that was cut off or never written (a full
  // disk, a copy interrupted), not a scene: played, it would be a silent 0-point frame.
  if (bytes == 0) throw InputError(path, 0, "empty scan (0 bytes; expected float32 x y z reflectance per point)");
  if (bytes % 16 != 0)
    throw InputError(path, 0, "size " + std::to_string(bytes) +
                                  " bytes is not a multiple of 16 (expected float32 x y z reflectance per point)");
  PointCloud scan(4, static_cast<Eigen::Index>(bytes / 16));
  if (bytes > 0) std::memcpy(scan.data(), data, bytes);
  if (!scan.allFinite()) {
    for (Eigen::Index i = 0; i < scan.cols(); ++i)
      if (!scan.col(i).allFinite())
        throw InputError(path, 0, "point " + std::to_string(i) + " has a NaN or infinite value");
  }
  return scan;
}

void writeVelodyne(const std::string& path, const PointCloud& scan) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) throw InputError(path, 0, "cannot open file for writing");
  std::fwrite(scan.data(), sizeof(float), static_cast<size_t>(scan.size()), f);
  closeWrite(f, path);
}

// ---------------- boxes ----------------

Box cameraToLidar(const CameraBox& cam, const Calib& calib) {
  Box b;
  b.center = calib.T_rect_velo().inverse() * cam.bottom_center;
  b.center.z() += 0.5 * cam.h;  // KITTI gives the bottom centre; the lidar z axis is up
  b.size = Eigen::Vector3d(cam.l, cam.w, cam.h);
  b.yaw = wrapAngle(-(cam.rotation_y + M_PI / 2));
  return b;
}

CameraBox lidarToCamera(const Box& box, const Calib& calib) {
  CameraBox cam;
  cam.l = box.size.x();
  cam.w = box.size.y();
  cam.h = box.size.z();
  cam.bottom_center = calib.T_rect_velo() * (box.center - Eigen::Vector3d(0, 0, 0.5 * cam.h));
  cam.rotation_y = wrapAngle(-box.yaw - M_PI / 2);
  return cam;
}

// ---------------- labels and detections ----------------

std::vector<LabelRow> readTrackingLabels(const std::string& path) {
  std::ifstream in = openText(path);
  return readTrackingLabels(in, path);
}

std::vector<LabelRow> readTrackingLabels(std::istream& in, const std::string& path) {
  std::vector<LabelRow> rows;
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    std::vector<std::string> t = splitWs(line);
    if (t.empty()) continue;
    if (t.size() != 17 && t.size() != 18)
      throw InputError(path, n, "expected 17 fields (frame id type truncated occluded alpha x1 y1 x2 y2 h w l x y z "
                                "rotation_y) or 18 (+ score), got " + std::to_string(t.size()));
    LabelRow r;
    r.frame = integer(t[0], path, n, "frame", 0, kMaxFrame);
    r.track_id = integer(t[1], path, n, "track id", -1, kMaxTrackId);
    r.type = t[2];
    r.truncated = number(t[3], path, n, "truncated");
    r.occluded = integer(t[4], path, n, "occluded");
    r.alpha = number(t[5], path, n, "alpha");
    for (int i = 0; i < 4; ++i) r.bbox2d[i] = number(t[6 + i], path, n, "bbox");
    r.box.h = number(t[10], path, n, "h");
    r.box.w = number(t[11], path, n, "w");
    r.box.l = number(t[12], path, n, "l");
    for (int i = 0; i < 3; ++i) r.box.bottom_center[i] = number(t[13 + i], path, n, "location");
    r.box.rotation_y = number(t[16], path, n, "rotation_y");
    if (t.size() == 18) r.score = number(t[17], path, n, "score");
    if (r.type != "DontCare") {  // KITTI's DontCare rows carry -1 sizes: no 3D box
      requirePositive(r.box.h, path, n, "h");
      requirePositive(r.box.w, path, n, "w");
      requirePositive(r.box.l, path, n, "l");
    }
    rows.push_back(r);
  }
  return rows;
}

void writeTrackingLabels(const std::string& path, const std::vector<LabelRow>& rows) {
  std::FILE* f = openWrite(path);
  for (const LabelRow& r : rows) {
    std::fprintf(f, "%d %d %s %.6f %d %.6f %.6f %.6f %.6f %.6f %.6f %.6f %.6f %.6f %.6f %.6f %.6f", r.frame,
                 r.track_id, r.type.c_str(), r.truncated, r.occluded, r.alpha, r.bbox2d[0], r.bbox2d[1],
                 r.bbox2d[2], r.bbox2d[3], r.box.h, r.box.w, r.box.l, r.box.bottom_center.x(),
                 r.box.bottom_center.y(), r.box.bottom_center.z(), r.box.rotation_y);
    if (r.score) {
      // Six decimals when they read back as the same number, else as many digits as that takes:
      // evaluators average a track's scores and compare the mean with other tracks' (sAMOTA), and
      // a value that does not survive the round trip ranks differently there than it did here.
      char six[64];
      std::snprintf(six, sizeof six, "%.6f", *r.score);
      if (std::strtod(six, nullptr) == *r.score)
        std::fprintf(f, " %s", six);
      else
        std::fprintf(f, " %.17g", *r.score);
    }
    std::fprintf(f, "\n");
  }
  closeWrite(f, path);
}

// ---------------- results rows: the box in the image ----------------

double observationAngle(const CameraBox& box) {
  return wrapAngle(box.rotation_y - std::atan2(box.bottom_center.x(), box.bottom_center.z()));
}

std::optional<ImageBox> projectToImage(const CameraBox& box, const Calib& calib, const ImageSize& image) {
  const Calib::Projection& P2 = calib.P[2];
  if (P2.isZero()) throw std::invalid_argument("the calibration has no P2: boxes cannot be projected into image_02");
  // Corners as the devkit builds them: length along x, width along z, height up (-y) from the
  // bottom centre, rotated by rotation_y about the camera's y axis.
  const double c = std::cos(box.rotation_y), s = std::sin(box.rotation_y);
  Eigen::Matrix3d Ry;
  Ry << c, 0, s, 0, 1, 0, -s, 0, c;
  std::array<Eigen::Vector3d, 8> corners;
  for (int i = 0; i < 8; ++i)
    corners[i] = box.bottom_center + Ry * Eigen::Vector3d((i & 1 ? 0.5 : -0.5) * box.l, i & 2 ? -box.h : 0.0,
                                                          (i & 4 ? 0.5 : -0.5) * box.w);
  // Depth along camera 2's axis is the third row of P2; cut every edge at the near plane.
  constexpr double kNear = 0.1;
  const auto depth = [&](const Eigen::Vector3d& p) { return P2.row(2).dot(p.homogeneous()); };
  std::vector<Eigen::Vector3d> visible;
  for (int i = 0; i < 8; ++i) {
    const double di = depth(corners[i]);
    if (di >= kNear) visible.push_back(corners[i]);
    for (int bit : {1, 2, 4}) {
      const int j = i | bit;
      if (j == i) continue;
      const double dj = depth(corners[j]);
      if ((di - kNear) * (dj - kNear) < 0) visible.push_back(corners[i] + (kNear - di) / (dj - di) * (corners[j] - corners[i]));
    }
  }
  if (visible.empty()) return std::nullopt;
  Eigen::Vector2d lo(INFINITY, INFINITY), hi(-INFINITY, -INFINITY);
  for (const Eigen::Vector3d& p : visible) {
    const Eigen::Vector3d uvw = P2 * p.homogeneous();
    const Eigen::Vector2d uv = uvw.head<2>() / uvw.z();
    lo = lo.cwiseMin(uv);
    hi = hi.cwiseMax(uv);
  }
  ImageBox out;
  out.unclipped << lo.x(), lo.y(), hi.x(), hi.y();
  const double xmax = image.width - 1, ymax = image.height - 1;
  out.bbox2d << std::clamp(lo.x(), 0.0, xmax), std::clamp(lo.y(), 0.0, ymax), std::clamp(hi.x(), 0.0, xmax),
      std::clamp(hi.y(), 0.0, ymax);
  if (!(out.bbox2d[2] > out.bbox2d[0] && out.bbox2d[3] > out.bbox2d[1])) return std::nullopt;  // outside the image
  out.alpha = observationAngle(box);
  return out;
}

std::optional<LabelRow> resultRow(LabelRow row, const Calib& calib, const ImageSize& image) {
  const std::optional<ImageBox> ib = projectToImage(row.box, calib, image);
  if (!ib) return std::nullopt;
  row.bbox2d = ib->bbox2d;
  row.alpha = ib->alpha;
  return row;
}

LabelRow unprojectedRow(int frame, const Box& box_lidar, const Calib& calib) {
  LabelRow row;
  row.frame = frame;
  row.track_id = box_lidar.id;
  row.type = box_lidar.type;
  row.alpha = -10;
  row.bbox2d = Eigen::Vector4d::Constant(-1);
  row.box = lidarToCamera(box_lidar, calib);
  row.score = box_lidar.score;
  return row;
}

std::optional<LabelRow> resultRow(int frame, const Box& box_lidar, const Calib& calib, const ImageSize& image) {
  return resultRow(unprojectedRow(frame, box_lidar, calib), calib, image);
}

std::vector<LabelRow> readCsvDetections(const std::string& path) {
  std::ifstream in = openText(path);
  return readCsvDetections(in, path);
}

std::vector<LabelRow> readCsvDetections(std::istream& in, const std::string& path) {
  std::vector<LabelRow> rows;
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::vector<std::string> t = splitComma(line);
    if (t.size() != 15)
      throw InputError(path, n, "expected 15 comma-separated fields (frame,type,x1,y1,x2,y2,score,h,w,l,x,y,z,rot_y,"
                                "alpha), got " + std::to_string(t.size()));
    LabelRow r;
    r.frame = integer(t[0], path, n, "frame", 0, kMaxFrame);
    const int type = integer(t[1], path, n, "type");
    static const std::map<int, std::string> kTypes = {{1, "Pedestrian"}, {2, "Car"}, {3, "Cyclist"}};
    auto it = kTypes.find(type);
    if (it == kTypes.end()) throw InputError(path, n, "type: expected 1 (Pedestrian), 2 (Car) or 3 (Cyclist), got " + t[1]);
    r.type = it->second;
    for (int i = 0; i < 4; ++i) r.bbox2d[i] = number(t[2 + i], path, n, "bbox");
    r.score = number(t[6], path, n, "score");
    r.box.h = number(t[7], path, n, "h");
    r.box.w = number(t[8], path, n, "w");
    r.box.l = number(t[9], path, n, "l");
    for (int i = 0; i < 3; ++i) r.box.bottom_center[i] = number(t[10 + i], path, n, "location");
    r.box.rotation_y = number(t[13], path, n, "rot_y");
    r.alpha = number(t[14], path, n, "alpha");
    requirePositive(r.box.h, path, n, "h");
    requirePositive(r.box.w, path, n, "w");
    requirePositive(r.box.l, path, n, "l");
    rows.push_back(r);
  }
  return rows;
}

std::vector<FrameBoxes> boxesByFrame(const std::vector<LabelRow>& rows, const Calib& calib, int num_frames,
                                     double min_score) {
  std::vector<FrameBoxes> out(num_frames);
  for (const LabelRow& r : rows) {
    if (r.frame >= num_frames) continue;  // rows for frames this sequence (slice) does not have
    if (r.score && *r.score < min_score) continue;
    Box b = cameraToLidar(r.box, calib);
    b.type = r.type;
    b.id = r.track_id;
    b.score = r.score.value_or(1.0);
    if (r.type == "DontCare") {
      // Real KITTI DontCare rows have no 3D box (-1 sizes); keep them only when they have one.
      if (r.box.h > 0 && r.box.w > 0 && r.box.l > 0) out[r.frame].dontcare.push_back(b);
    } else {
      out[r.frame].boxes.push_back(b);
    }
  }
  return out;
}

// ---------------- oxts ----------------

std::vector<OxtsRecord> readOxts(const std::string& path) {
  std::ifstream in = openText(path);
  return readOxts(in, path);
}

std::vector<OxtsRecord> readOxts(std::istream& in, const std::string& path) {
  std::vector<OxtsRecord> rows;
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    std::vector<std::string> t = splitWs(line);
    if (t.empty()) continue;
    if (t.size() != 30)
      throw InputError(path, n, "expected 30 oxts fields (lat lon alt roll pitch yaw ... orimode), got " +
                                    std::to_string(t.size()));
    OxtsRecord r;
    for (int i = 0; i < 30; ++i) r[i] = number(t[i], path, n, "field " + std::to_string(i + 1));
    rows.push_back(r);
  }
  return rows;
}

void writeOxts(const std::string& path, const std::vector<OxtsRecord>& rows) {
  std::FILE* f = openWrite(path);
  for (const OxtsRecord& r : rows) {
    // lat/lon need ~1e-11 degrees to keep the round trip within a micrometre.
    for (int i = 0; i < 30; ++i) std::fprintf(f, i < 25 ? "%s%.14g" : "%s%.0f", i ? " " : "", r[i]);
    std::fprintf(f, "\n");
  }
  closeWrite(f, path);
}

std::vector<Pose> oxtsToLidarPoses(const std::vector<OxtsRecord>& rows, const Pose& T_velo_imu) {
  std::vector<Pose> poses;
  if (rows.empty()) return poses;
  const double scale = std::cos(rows[0][0] * M_PI / 180.0);
  const Pose T_imu_velo = T_velo_imu.inverse();
  Pose T0_inv = Pose::Identity();
  for (size_t i = 0; i < rows.size(); ++i) {
    const OxtsRecord& r = rows[i];
    Pose T_w_imu = Pose::Identity();
    T_w_imu.translation() << scale * r[1] * M_PI * kEarthRadius / 180.0,
        scale * kEarthRadius * std::log(std::tan((90.0 + r[0]) * M_PI / 360.0)), r[2];
    T_w_imu.linear() = rpyToR(r[3], r[4], r[5]);
    const Pose T_w_velo = T_w_imu * T_imu_velo;
    if (i == 0) T0_inv = T_w_velo.inverse();
    poses.push_back(T0_inv * T_w_velo);
  }
  return poses;
}

std::vector<OxtsRecord> lidarPosesToOxts(const std::vector<Pose>& poses, const Pose& T_velo_imu, double lat0_deg,
                                         double lon0_deg, double alt0) {
  const double scale = std::cos(lat0_deg * M_PI / 180.0);
  // Place the first IMU position exactly at (lat0, lon0, alt0) so the scale the reader derives from
  // the first record is the one used here.
  const Eigen::Vector3d imu0(scale * lon0_deg * M_PI * kEarthRadius / 180.0,
                             scale * kEarthRadius * std::log(std::tan((90.0 + lat0_deg) * M_PI / 360.0)), alt0);
  Pose A = Pose::Identity();
  A.translation() = imu0 - (poses.empty() ? Pose::Identity() : poses[0]) * T_velo_imu.translation();
  std::vector<OxtsRecord> rows;
  for (const Pose& P : poses) {
    const Pose T_w_imu = A * P * T_velo_imu;
    const Eigen::Matrix3d R = T_w_imu.linear();
    OxtsRecord r{};
    const Eigen::Vector3d t = T_w_imu.translation();
    r[0] = 360.0 / M_PI * std::atan(std::exp(t.y() / (scale * kEarthRadius))) - 90.0;
    r[1] = t.x() * 180.0 / (scale * M_PI * kEarthRadius);
    r[2] = t.z();
    // R = Rz(yaw) Ry(pitch) Rx(roll)
    r[4] = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
    r[3] = std::atan2(R(2, 1), R(2, 2));
    r[5] = std::atan2(R(1, 0), R(0, 0));
    r[25] = 4;  // navstat: RTK fix
    r[26] = 10; // numsats
    r[27] = r[28] = r[29] = 4;
    rows.push_back(r);
  }
  return rows;
}

// ---------------- poses and times ----------------

std::vector<Pose> readPoses(const std::string& path) {
  std::ifstream in = openText(path);
  return readPoses(in, path);
}

std::vector<Pose> readPoses(std::istream& in, const std::string& path) {
  std::vector<Pose> poses;
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    std::vector<std::string> t = splitWs(line);
    if (t.empty()) continue;
    if (t.size() != 12)
      throw InputError(path, n, "expected 12 numbers (a 3x4 row-major pose), got " + std::to_string(t.size()));
    std::vector<double> v;
    for (const auto& s : t) v.push_back(number(s, path, n, "pose"));
    const Pose T = rowsToPose(v);
    const double off = (T.linear().transpose() * T.linear() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
    if (off > 1e-3 || T.linear().determinant() < 0)
      throw InputError(path, n, "pose: expected a rotation in the 3x3 block (R^T R = I, det 1), off by " +
                                    std::to_string(off));
    poses.push_back(T);
  }
  return poses;
}

void writePoses(const std::string& path, const std::vector<Pose>& poses) {
  std::FILE* f = openWrite(path);
  for (const Pose& T : poses) {
    const Eigen::Matrix<double, 3, 4> m = T.matrix().topRows<3>();
    for (int i = 0; i < 12; ++i) std::fprintf(f, i ? " %.12e" : "%.12e", m(i / 4, i % 4));
    std::fprintf(f, "\n");
  }
  closeWrite(f, path);
}

std::vector<double> readTimes(const std::string& path) {
  std::ifstream in = openText(path);
  return readTimes(in, path);
}

std::vector<double> readTimes(std::istream& in, const std::string& path) {
  std::vector<double> times;
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    std::vector<std::string> t = splitWs(line);
    if (t.empty()) continue;
    if (t.size() != 1) throw InputError(path, n, "expected one time in seconds, got " + std::to_string(t.size()) + " fields");
    times.push_back(number(t[0], path, n, "time"));
  }
  return times;
}

// ---------------- sequences ----------------

SequencePaths locateSequence(const std::string& root, const std::string& sequence) {
  if (!fs::is_directory(root)) throw InputError(root, 0, "data set root is not a directory");
  SequencePaths p;
  auto ifExists = [](const fs::path& f) { return fs::exists(f) ? f.string() : std::string(); };
  fs::path tracking = fs::path(root) / "training";
  if (!fs::is_directory(tracking / "velodyne") && fs::is_directory(fs::path(root) / "velodyne")) tracking = root;
  const fs::path odometry = fs::path(root) / "sequences" / sequence;
  const bool tracking_scans = fs::is_directory(tracking / "velodyne" / sequence);
  // A tracking sequence without scans (labels, calib and detections: the usual MOT setting).
  const bool tracking_no_scans = !tracking_scans && !fs::is_directory(odometry / "velodyne") &&
                                 (fs::exists(tracking / "label_02" / (sequence + ".txt")) ||
                                  fs::exists(tracking / "calib" / (sequence + ".txt")));
  if (tracking_scans || tracking_no_scans) {
    p.layout = SequencePaths::Layout::Tracking;
    if (tracking_scans) p.velodyne_dir = (tracking / "velodyne" / sequence).string();
    p.calib = (tracking / "calib" / (sequence + ".txt")).string();
    p.labels = ifExists(tracking / "label_02" / (sequence + ".txt"));
    p.oxts = ifExists(tracking / "oxts" / (sequence + ".txt"));
    p.poses = ifExists(tracking / "poses" / (sequence + ".txt"));
    p.poses_are_lidar = true;
  } else if (fs::is_directory(odometry / "velodyne")) {
    p.layout = SequencePaths::Layout::Odometry;
    p.velodyne_dir = (odometry / "velodyne").string();
    p.calib = (odometry / "calib.txt").string();
    p.times = ifExists(odometry / "times.txt");
    p.poses = ifExists(fs::path(root) / "poses" / (sequence + ".txt"));
    p.poses_are_lidar = false;
  } else {
    throw InputError(root, 0, "no sequence '" + sequence + "': expected " + (tracking / "velodyne" / sequence).string() +
                                  " (KITTI tracking) or " + (odometry / "velodyne").string() + " (KITTI odometry)");
  }
  if (!fs::exists(p.calib)) throw InputError(p.calib, 0, "calibration file missing");
  if (p.velodyne_dir.empty()) return p;  // no scans: SequenceReader counts frames from labels and detections
  int n = 0;
  long highest = -1;  // the highest-numbered scan there: where the sequence ends
  for (const auto& e : fs::directory_iterator(p.velodyne_dir)) {
    if (e.path().extension() != ".bin") continue;
    ++n;
    const std::string stem = e.path().stem().string();
    char* end = nullptr;
    const long i = std::strtol(stem.c_str(), &end, 10);
    if (!stem.empty() && end && *end == '\0') highest = std::max(highest, i);
  }
  for (int i = 0; i < n; ++i) {
    char name[32], last[32];
    std::snprintf(name, sizeof name, "%06d.bin", i);
    std::snprintf(last, sizeof last, "%06ld.bin", std::max<long>(highest, n - 1));
    if (!fs::exists(fs::path(p.velodyne_dir) / name))
      throw InputError(p.velodyne_dir, 0, std::string("expected scans 000000.bin .. ") + last +
                                              " without gaps; missing " + name);
  }
  if (n == 0) throw InputError(p.velodyne_dir, 0, "no .bin scans");
  p.num_frames = n;
  return p;
}

bool classesCompatible(const std::string& a, const std::string& b) {
  auto canon = [](const std::string& s) {
    if (s == "Van") return std::string("Car");
    if (s == "Person_sitting") return std::string("Pedestrian");
    return s;
  };
  return canon(a) == canon(b);
}

// ---------------- SequenceReader ----------------

std::vector<LabelRow> readDetectionRows(const std::string& path) {
  std::ifstream in = openText(path);
  std::string first;
  while (std::getline(in, first) && first.find_first_not_of(" \t\r") == std::string::npos) {
  }
  const bool csv = first.find(',') != std::string::npos;
  return csv ? readCsvDetections(path) : readTrackingLabels(path);
}

SequenceReader::SequenceReader(const std::string& root, const std::string& sequence,
                               const std::vector<std::string>& detection_paths, double min_detection_score,
                               double frame_period_s)
    : paths_(locateSequence(root, sequence)), calib_(readCalib(paths_.calib)), frame_period_s_(frame_period_s) {
  const std::vector<LabelRow> label_rows = paths_.labels.empty() ? std::vector<LabelRow>() : readTrackingLabels(paths_.labels);
  std::vector<std::vector<LabelRow>> detection_rows;
  for (std::string path : detection_paths) {
    if (fs::is_directory(path)) path = (fs::path(path) / (sequence + ".txt")).string();
    detection_rows.push_back(readDetectionRows(path));
  }
  if (!hasScans()) {
    // Without scans the sequence is as long as its labels and detections say.
    int last = -1;
    for (const LabelRow& r : label_rows) last = std::max(last, r.frame);
    for (const auto& rows : detection_rows)
      for (const LabelRow& r : rows) last = std::max(last, r.frame);
    if (last < 0)
      throw InputError(paths_.labels.empty() ? paths_.calib : paths_.labels, 0,
                       "sequence " + sequence + " has no scans (no velodyne/), no labels and no detections: nothing to read");
    paths_.num_frames = last + 1;
  }
  const int n = paths_.num_frames;
  // Ground-truth ego poses: a poses file wins over oxts.
  if (!paths_.poses.empty()) {
    std::vector<Pose> poses = readPoses(paths_.poses);
    if (!paths_.poses_are_lidar) {
      const Pose Tr = calib_.T_cam_velo;
      for (Pose& T : poses) T = Tr.inverse() * T * Tr;
    }
    gt_poses_ = std::move(poses);
  } else if (!paths_.oxts.empty()) {
    if (!calib_.T_velo_imu)
      throw InputError(paths_.calib, 0, "oxts poses need the imu-to-velodyne transform (Tr_imu_velo or Tr_imu_to_velo)");
    gt_poses_ = oxtsToLidarPoses(readOxts(paths_.oxts), *calib_.T_velo_imu);
  }
  if (!gt_poses_.empty() && static_cast<int>(gt_poses_.size()) < n)
    throw InputError(!paths_.poses.empty() ? paths_.poses : paths_.oxts, 0,
                     "has " + std::to_string(gt_poses_.size()) + " poses, expected one per scan (" + std::to_string(n) + ")");
  if (!paths_.labels.empty()) labels_ = boxesByFrame(label_rows, calib_, n);
  if (!paths_.times.empty()) {
    times_ = readTimes(paths_.times);
    if (static_cast<int>(times_.size()) < n)
      throw InputError(paths_.times, 0, "has " + std::to_string(times_.size()) + " times, expected " + std::to_string(n));
  }
  if (!detection_paths.empty()) detections_.assign(n, {});
  for (const auto& rows : detection_rows) {
    const auto frames = boxesByFrame(rows, calib_, n, min_detection_score);
    for (int i = 0; i < n; ++i)
      detections_[i].boxes.insert(detections_[i].boxes.end(), frames[i].boxes.begin(), frames[i].boxes.end());
  }
  // Detector output carries no track ids.
  for (auto& f : detections_)
    for (Box& b : f.boxes) b.id = -1;
}

Frame SequenceReader::read(int index) const {
  if (index < 0 || index >= paths_.num_frames)
    throw std::out_of_range("frame " + std::to_string(index) + " outside 0.." + std::to_string(paths_.num_frames - 1));
  Frame f;
  f.index = index;
  const double t = times_.empty() ? index * frame_period_s_ : times_[index];
  f.utime = static_cast<int64_t>(std::llround(t * 1e6));
  char name[32];
  std::snprintf(name, sizeof name, "%06d.bin", index);
  if (hasScans()) f.scan = readVelodyne((fs::path(paths_.velodyne_dir) / name).string());
  if (!detections_.empty()) f.detections = detections_[index].boxes;
  if (!labels_.empty()) {
    f.labels = labels_[index].boxes;
    f.dontcare = labels_[index].dontcare;
  }
  if (!gt_poses_.empty()) f.gt_pose = gt_poses_[index];
  return f;
}

}  // namespace dlslot::kitti
