#include "summary_renderer.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "drawing.hpp"
#include "grid.hpp"
#include "palette.hpp"
#include "view_transform.hpp"

namespace dlslot::renderer {
namespace {

using Path = std::map<int, Eigen::Vector3d>;

// Fits the run into the image between the title panel and the bottom edge: every path and track,
// but with ground truth only what lies within reach of it, so an estimate that diverges cannot
// shrink the real scene to a dot (it leaves the view and the text says so).
ViewTransform fitView(const RunSummary& run, const SummaryConfig& cfg) {
  Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
  auto grow = [&](const Eigen::Vector3d& p) {
    lo = lo.cwiseMin(p.head<2>());
    hi = hi.cwiseMax(p.head<2>());
  };
  for (const auto& [f, p] : run.gt_path) grow(p);
  // With ground truth, estimates count only within reach of it: drift stays in view,
  // divergence does not decide the scale.
  const Eigen::Vector2d gt_lo = lo, gt_hi = hi;
  const double reach = run.gt_path.empty() ? 1e300 : std::max(50.0, (gt_hi - gt_lo).maxCoeff());
  auto near = [&](const Eigen::Vector3d& p) {
    return ((gt_lo - p.head<2>()).cwiseMax(p.head<2>() - gt_hi)).maxCoeff() <= reach;
  };
  for (const Path* path : {&run.odometry_path, &run.slot_path})
    for (const auto& [f, p] : *path)
      if (near(p)) grow(p);
  for (const TrackPath& t : run.tracks)
    for (const auto& p : t.positions)
      if (near(p)) grow(p);
  if (lo.x() > hi.x()) lo = hi = Eigen::Vector2d::Zero();
  const Eigen::Vector2d mid = 0.5 * (lo + hi);
  const Eigen::Vector2d extent = (hi - lo).cwiseMax(40.0) + Eigen::Vector2d(20.0, 20.0);  // >= 40 m, 10 m margins

  const cv::Rect content(30, 120, cfg.width - 60, cfg.height - 150);
  const double mpp = std::max(extent.x() / content.width, extent.y() / content.height);
  const double dx = content.x + 0.5 * content.width - 0.5 * cfg.width;
  const double dy = content.y + 0.5 * content.height - 0.5 * cfg.height;
  return ViewTransform::worldWindow(Eigen::Vector2d(mid.x() - dx * mpp, mid.y() + dy * mpp), mpp, cfg.width,
                                    cfg.height);
}

// Kept-point density, log-scaled against the 98th percentile of occupied pixels.
void drawMap(cv::Mat& img, const DensityMap& map, const ViewTransform& view) {
  cv::Mat density(img.rows, img.cols, CV_32F, cv::Scalar(0));
  const ViewTransform::Projection& P = view.worldToPixel();
  map.forEach([&](double x, double y, uint32_t count) {
    const Eigen::Vector2d px = P * Eigen::Vector4d(x, y, 0, 1);
    if (px.x() < 0 || px.y() < 0 || px.x() >= img.cols || px.y() >= img.rows) return;
    density.at<float>(static_cast<int>(px.y()), static_cast<int>(px.x())) += static_cast<float>(count);
  });
  // Cells larger than a pixel fill their area.
  const int cell_px = static_cast<int>(std::lround(map.cellSize() / view.metresPerPixel()));
  if (cell_px > 1) cv::dilate(density, density, cv::Mat::ones(cell_px, cell_px, CV_8U));
  std::vector<float> occupied;
  for (int r = 0; r < density.rows; ++r)
    for (int c = 0; c < density.cols; ++c)
      if (float d = density.at<float>(r, c); d > 0) occupied.push_back(std::log1p(d));
  if (occupied.empty()) return;
  auto nth = occupied.begin() + static_cast<long>(0.98 * (occupied.size() - 1));
  std::nth_element(occupied.begin(), nth, occupied.end());
  const float ref = std::max(*nth, 1e-3f);
  const cv::Vec3f dark(54, 47, 42), bright(180, 170, 160);
  for (int r = 0; r < density.rows; ++r) {
    const float* d = density.ptr<float>(r);
    cv::Vec3b* px = img.ptr<cv::Vec3b>(r);
    for (int c = 0; c < density.cols; ++c) {
      if (d[c] <= 0) continue;
      const float t = std::min(1.0f, std::log1p(d[c]) / ref);
      const cv::Vec3f v = dark + t * (bright - dark);
      px[c] = cv::Vec3b(static_cast<uchar>(v[0]), static_cast<uchar>(v[1]), static_cast<uchar>(v[2]));
    }
  }
}

Polygon pixels(const Path& path, const ViewTransform& view) {
  Polygon out;
  for (const auto& [f, p] : path) out.push_back(view.fromWorld(p));
  return out;
}

double length(const Path& path) {
  double len = 0;
  for (auto it = path.begin(); it != path.end() && std::next(it) != path.end(); ++it)
    len += (std::next(it)->second - it->second).norm();
  return len;
}

// Position error against ground truth over the frames both have (no alignment: both start at
// the identity in the same world frame).
struct PathError {
  int frames = 0;
  double end = 0, rms = 0, max = 0;
};
PathError errorAgainst(const Path& est, const Path& gt) {
  PathError e;
  for (const auto& [f, p] : est) {
    auto g = gt.find(f);
    if (g == gt.end()) continue;
    const double d = (p - g->second).norm();
    e.rms += d * d;
    e.end = d;
    e.max = std::max(e.max, d);
    ++e.frames;
  }
  if (e.frames) e.rms = std::sqrt(e.rms / e.frames);
  return e;
}

void drawTracks(cv::Mat& img, const RunSummary& run, const ViewTransform& view) {
  for (const TrackPath& t : run.tracks) {
    if (t.is_dynamic) continue;
    const cv::Scalar c = trackColour(t.id);
    Polygon box;
    for (const auto& q : footprint(t.last_pose, t.size)) box.push_back(view.fromWorld(q));
    dashedPolygon(img, box, c, 1, 4, 3);
  }
  LabelPlacer labels;
  for (const TrackPath& t : run.tracks) {
    if (!t.is_dynamic || t.positions.empty()) continue;
    const cv::Scalar c = trackColour(t.id);
    Polygon px;
    for (const auto& p : t.positions) px.push_back(view.fromWorld(p));
    polyline(img, px, false, c, 2);
    cv::circle(img, subpixel(px.front()), 3 << kShift, c, 1, cv::LINE_AA, kShift);
    // Its heading at the end, a fixed length so short tracks still show it.
    const Eigen::Vector2d end = px.back();
    const Eigen::Vector2d head = view.fromWorld(t.last_pose * Eigen::Vector3d(1, 0, 0)) - view.fromWorld(t.last_pose.translation());
    if (head.norm() > 1e-9) arrow(img, end, end + head.normalized() * 14.0, c, 2);
    labels.place(img, strf("%d %s", t.id, t.type.c_str()), cv::Point(static_cast<int>(end.x()) + 8, static_cast<int>(end.y()) + 4), c);
  }
}

}  // namespace

cv::Mat renderSummary(const RunSummary& run, const DensityMap* map, const SummaryConfig& cfg) {
  cv::Mat img = solidImage(cfg.width, cfg.height, colour::kBackground);
  const ViewTransform view = fitView(run, cfg);
  worldGrid(img, view);
  if (map && !map->empty()) drawMap(img, *map, view);
  drawTracks(img, run, view);

  const std::pair<const Path*, cv::Scalar> paths[] = {{&run.gt_path, colour::kGroundTruth},
                                                      {&run.odometry_path, colour::kOdometry},
                                                      {&run.slot_path, colour::kSlot}};
  for (const auto& [path, c] : paths) {
    if (path->empty()) continue;
    const Polygon px = pixels(*path, view);
    polyline(img, px, false, c, 2);
    cv::circle(img, subpixel(px.back()), 4 << kShift, c, cv::FILLED, cv::LINE_AA, kShift);
  }
  for (const auto& [path, c] : paths)
    if (!path->empty()) {
      const Eigen::Vector2d start = view.fromWorld(path->begin()->second);
      cv::circle(img, subpixel(start), 6 << kShift, colour::kText, 2, cv::LINE_AA, kShift);
      label(img, "start", cv::Point(static_cast<int>(start.x()) + 10, static_cast<int>(start.y()) + 18), colour::kText);
      break;
    }

  // Title and numbers.
  std::vector<TextLine> lines;
  lines.push_back({strf("DL-SLOT run summary    frames %d-%d (%d drawn)    %.1f s", run.first_frame, run.last_frame,
                        run.frames_rendered, run.duration_s),
                   colour::kText, kTitleFont});
  std::string lengths = "path length";
  if (!run.slot_path.empty()) lengths += strf("    DL-SLOT %.1f m", length(run.slot_path));
  if (!run.odometry_path.empty()) lengths += strf("    odometry %.1f m", length(run.odometry_path));
  if (!run.gt_path.empty()) lengths += strf("    ground truth %.1f m", length(run.gt_path));
  lines.push_back({lengths, colour::kText});
  if (!run.gt_path.empty()) {
    std::string err = "position error vs ground truth (no alignment)";
    for (const auto& [name, path] : {std::pair<const char*, const Path*>{"DL-SLOT", &run.slot_path},
                                     std::pair<const char*, const Path*>{"odometry", &run.odometry_path}}) {
      const PathError e = errorAgainst(*path, run.gt_path);
      if (e.frames) err += strf("    %s: end %.2f m, RMS %.2f m", name, e.end, e.rms);
    }
    lines.push_back({err, colour::kText});
    for (const auto& [name, path] : {std::pair<const char*, const Path*>{"DL-SLOT", &run.slot_path},
                                     std::pair<const char*, const Path*>{"odometry", &run.odometry_path}}) {
      const bool leaves = std::any_of(path->begin(), path->end(), [&](const auto& fp) {
        const Eigen::Vector2d px = view.fromWorld(fp.second);
        return px.x() < 0 || px.y() < 0 || px.x() >= img.cols || px.y() >= img.rows;
      });
      if (leaves)
        lines.push_back({strf("%s leaves the view: up to %.1f m from ground truth", name,
                              errorAgainst(*path, run.gt_path).max),
                         colour::kWarning});
    }
  }
  int dynamic = 0;
  for (const TrackPath& t : run.tracks) dynamic += t.is_dynamic;
  lines.push_back({strf("tracks %zu    dynamic %d    static %zu", run.tracks.size(), dynamic, run.tracks.size() - dynamic),
                   colour::kText});
  textPanel(img, lines, cv::Point(12, 12));

  using S = LegendEntry::Swatch;
  std::vector<LegendEntry> entries = {{S::Line, colour::kSlot, "DL-SLOT"},
                                      {S::Line, colour::kOdometry, "odometry"},
                                      {S::Line, colour::kGroundTruth, "ground truth"},
                                      {S::Line, trackColour(0), "dynamic track path: id class"},
                                      {S::DashedBox, trackColour(3), "static track (last pose)"}};
  if (map && !map->empty())
    entries.push_back({S::Dots, cv::Scalar(110, 100, 92), "map: kept points at the ego estimate", cv::Scalar(180, 170, 160)});
  legend(img, entries);
  scaleBar(img, view.metresPerPixel());
  return img;
}

}  // namespace dlslot::renderer
