#include "mapper/map_output.hpp"

#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "trajectory.hpp"

namespace dlslot::mapper {

void writePcd(const std::string& path, const PointCloud& points) {
  pcl::PointCloud<pcl::PointXYZI> cloud;
  cloud.resize(points.cols());
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    pcl::PointXYZI& p = cloud[i];
    p.x = points(0, i);
    p.y = points(1, i);
    p.z = points(2, i);
    p.intensity = points(3, i);
  }
  cloud.width = static_cast<uint32_t>(cloud.size());
  cloud.height = 1;
  // An empty cloud is a valid map (nothing static seen); PCL refuses to write one, so its header alone.
  if (cloud.empty()) {
    std::ofstream out(path);
    out << "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z intensity\nSIZE 4 4 4 4\n"
           "TYPE F F F F\nCOUNT 1 1 1 1\nWIDTH 0\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 0\nDATA binary\n";
    if (!out) throw std::runtime_error(path + ": cannot write");
    return;
  }
  if (pcl::io::savePCDFileBinary(path, cloud) != 0) throw std::runtime_error(path + ": cannot write PCD");
}

PointCloud readPcd(const std::string& path) {
  pcl::PointCloud<pcl::PointXYZI> cloud;
  if (pcl::io::loadPCDFile(path, cloud) != 0) throw std::runtime_error(path + ": cannot read PCD");
  PointCloud out(4, static_cast<Eigen::Index>(cloud.size()));
  for (size_t i = 0; i < cloud.size(); ++i) out.col(static_cast<Eigen::Index>(i)) << cloud[i].x, cloud[i].y, cloud[i].z, cloud[i].intensity;
  return out;
}

MapImageStats writeMapImage(const std::string& path, const Mapper& mapper, int max_side_px) {
  const PointCloud pts = mapper.map().cloud();
  const std::vector<std::pair<int, Pose>> traj = mapper.mapTrajectory();
  Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
  for (Eigen::Index i = 0; i < pts.cols(); ++i) {
    lo = lo.cwiseMin(pts.col(i).head<2>().cast<double>());
    hi = hi.cwiseMax(pts.col(i).head<2>().cast<double>());
  }
  for (const auto& [f, T] : traj) {
    lo = lo.cwiseMin(T.translation().head<2>());
    hi = hi.cwiseMax(T.translation().head<2>());
  }
  if (!(hi.x() >= lo.x())) lo = hi = Eigen::Vector2d::Zero();
  lo -= Eigen::Vector2d::Constant(5);
  hi += Eigen::Vector2d::Constant(5);
  MapImageStats s;
  s.metres_per_pixel = std::max(mapper.map().voxelSize(), (hi - lo).maxCoeff() / max_side_px);
  s.width = static_cast<int>(std::ceil((hi.x() - lo.x()) / s.metres_per_pixel)) + 1;
  s.height = static_cast<int>(std::ceil((hi.y() - lo.y()) / s.metres_per_pixel)) + 1;
  // x to the right, y up: row = (hi.y - y) / m.
  auto pixel = [&](const Eigen::Vector3d& p) {
    return cv::Point(static_cast<int>((p.x() - lo.x()) / s.metres_per_pixel),
                     static_cast<int>((hi.y() - p.y()) / s.metres_per_pixel));
  };
  // Height range: the 2nd to 98th percentile of the map's z, so a few tall points do not wash it out.
  std::vector<float> z(static_cast<size_t>(pts.cols()));
  for (Eigen::Index i = 0; i < pts.cols(); ++i) z[static_cast<size_t>(i)] = pts(2, i);
  float zlo = 0, zhi = 1;
  if (!z.empty()) {
    // Two selections, not a sort of a million heights.
    const auto lo_it = z.begin() + static_cast<std::ptrdiff_t>(z.size() * 2 / 100);
    const auto hi_it = z.begin() + static_cast<std::ptrdiff_t>(z.size() * 98 / 100);
    std::nth_element(z.begin(), lo_it, z.end());
    zlo = *lo_it;
    std::nth_element(lo_it, hi_it, z.end());
    zhi = std::max(zlo + 0.1f, *hi_it);
  }
  cv::Mat top(s.height, s.width, CV_32F, cv::Scalar(-1e9));
  for (Eigen::Index i = 0; i < pts.cols(); ++i) {
    const cv::Point px = pixel(pts.col(i).head<3>().cast<double>());
    if (px.x < 0 || px.y < 0 || px.x >= s.width || px.y >= s.height) continue;
    float& v = top.at<float>(px);
    v = std::max(v, pts(2, i));
  }
  cv::Mat level(s.height, s.width, CV_8U, cv::Scalar(0)), mask = top > -1e8;
  top.forEach<float>([&](float& v, const int* pos) {
    if (v > -1e8) level.at<uchar>(pos[0], pos[1]) = static_cast<uchar>(std::clamp(255.0f * (v - zlo) / (zhi - zlo), 0.0f, 255.0f));
  });
  cv::Mat colour, image(s.height, s.width, CV_8UC3, cv::Scalar(0, 0, 0));
  cv::applyColorMap(level, colour, cv::COLORMAP_TURBO);
  colour.copyTo(image, mask);
  std::vector<cv::Point> line;
  for (const auto& [f, T] : traj) line.push_back(pixel(T.translation()));
  if (line.size() > 1) cv::polylines(image, line, false, cv::Scalar(255, 255, 255), 2, cv::LINE_AA);
  const auto& kfs = mapper.keyframes();
  for (const LoopEvent& e : mapper.loops().allEvents()) {
    if (!e.verdict.accepted || e.query_keyframe >= int(kfs.size())) continue;
    cv::line(image, pixel(kfs[e.match_keyframe].map.translation()), pixel(kfs[e.query_keyframe].map.translation()),
             cv::Scalar(0, 0, 255), 3, cv::LINE_AA);
  }
  if (!line.empty()) cv::circle(image, line.front(), 6, cv::Scalar(0, 255, 0), -1, cv::LINE_AA);
  // The legend in two lines, scaled down to the image's width (a short drive makes a narrow image).
  char scale_line[96], count_line[64];
  std::snprintf(scale_line, sizeof scale_line, "%.2f m/px, height %.1f..%.1f m (blue..red)", s.metres_per_pixel, zlo, zhi);
  std::snprintf(count_line, sizeof count_line, "%d keyframes, %d loops", static_cast<int>(kfs.size()),
                mapper.loops().accepted());
  int baseline = 0;
  const int widest = cv::getTextSize(scale_line, cv::FONT_HERSHEY_SIMPLEX, 0.6, 1, &baseline).width;
  const double font = 0.6 * std::min(1.0, (s.width - 20.0) / std::max(1, widest));
  cv::putText(image, scale_line, cv::Point(10, 10 + static_cast<int>(25 * font)), cv::FONT_HERSHEY_SIMPLEX, font,
              cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  cv::putText(image, count_line, cv::Point(10, 10 + static_cast<int>(55 * font)), cv::FONT_HERSHEY_SIMPLEX, font,
              cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  if (!cv::imwrite(path, image)) throw std::runtime_error(path + ": cannot write PNG");
  return s;
}

std::vector<std::string> writeMapOutputs(const std::string& dir, const Mapper& mapper) {
  namespace fs = std::filesystem;
  fs::create_directories(dir);
  const fs::path d(dir);
  writePcd((d / "map.pcd").string(), mapper.map().cloud());
  writePcd((d / "map_removed.pcd").string(), mapper.removed().cloud());
  eval::Trajectory t;
  const std::vector<std::pair<int, Pose>> traj = mapper.mapTrajectory();
  const std::vector<int64_t> utimes = mapper.frameUtimes();
  for (size_t i = 0; i < traj.size(); ++i) t.add(traj[i].first, utimes[i] * 1e-6, traj[i].second);
  eval::writeTrajectory((d / "trajectory_map_kitti.txt").string(), t, eval::TrajectoryFormat::Kitti);
  eval::writeTrajectory((d / "trajectory_map_tum.txt").string(), t, eval::TrajectoryFormat::Tum);
  {
    std::ofstream kf(d / "map_keyframes.txt");
    // 9 digits: the evaluation places each keyframe's points with these poses and finds the map's
    // points among them (to a few mm at a kilometre).
    kf.precision(9);
    kf << "# frame kept_points removed_points, then T_map_lidar as 12 numbers (3x4 row-major), then the T_map_lidar "
          "its points were inserted with (the grid they were counted on; differs after a loop correction)\n";
    for (const KeyframeRecord& k : mapper.keyframes()) {
      kf << k.frame << " " << k.kept << " " << k.removed;
      for (const Pose* T : {&k.map, &k.inserted})
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 4; ++c) kf << " " << T->matrix()(r, c);
      kf << "\n";
    }
    if (!kf) throw std::runtime_error((d / "map_keyframes.txt").string() + ": cannot write");
  }
  {
    std::ofstream lp(d / "map_loops.txt");
    lp.precision(9);
    lp << "# query_frame match_frame accepted descriptor_distance inlier_ratio rmse_m, T_match_query as 12 numbers "
          "(3x4 row-major), the share of its inliers kept when moved false_loop_m (0: not reached), then the reason "
          "it was refused\n";
    for (const LoopEvent& e : mapper.loops().allEvents()) {
      const Registration& r = e.verdict.registration;
      lp << e.query_frame << " " << e.match_frame << " " << (e.verdict.accepted ? 1 : 0) << " " << e.descriptor_distance
         << " " << r.inlier_ratio << " " << r.rmse_m;
      for (int i = 0; i < 3; ++i)
        for (int c = 0; c < 4; ++c) lp << " " << r.T_match_query.matrix()(i, c);
      lp << " " << e.verdict.shifted_inlier_share << " " << (e.verdict.accepted ? "-" : e.verdict.reason) << "\n";
    }
    if (!lp) throw std::runtime_error((d / "map_loops.txt").string() + ": cannot write");
  }
  writeMapImage((d / "map.png").string(), mapper);
  return {"map.pcd", "map_removed.pcd", "trajectory_map_kitti.txt", "trajectory_map_tum.txt", "map_keyframes.txt",
          "map_loops.txt", "map.png"};
}

}  // namespace dlslot::mapper
