#include "bev_renderer.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "dlslot/box_filter.hpp"
#include "drawing.hpp"
#include "grid.hpp"
#include "palette.hpp"
#include "view_transform.hpp"

namespace dlslot::renderer {
namespace {

struct PointCounts {
  int total = 0, removed = 0;
};

// Points by direct pixel writes: one shading code per pixel (the highest point wins, removed
// over kept), then one pass turning codes into colours.
PointCounts drawPoints(cv::Mat& img, const RenderInput& in, const ViewTransform& view, const ViewConfig& cfg) {
  PointCounts counts;
  counts.total = static_cast<int>(in.scan.cols());
  std::vector<bool> removed;
  const bool filtered = !in.has_odometry || in.odometry_filtered;  // A-LOAM (unfiltered) removes nothing
  if (filtered && in.has_detections && !in.detections.empty())
    removed = objectPoints(in.scan, in.detections, cfg.removal_margin_m,  // the odometry's own test
                           cfg.removal_ground_clearance_m);
  for (bool r : removed) counts.removed += r;
  if (!cfg.layers.points && !cfg.layers.removed_points) return counts;

  const PointShading shading(cfg.min_height_m, cfg.max_height_m);
  cv::Mat codes(img.rows, img.cols, CV_8U, cv::Scalar(0));
  const Eigen::Matrix<float, 2, 4> P = view.lidarToPixel().cast<float>();
  const float w = static_cast<float>(img.cols), h = static_cast<float>(img.rows);
  const float* data = in.scan.data();
  for (Eigen::Index i = 0; i < in.scan.cols(); ++i) {
    const bool is_removed = !removed.empty() && removed[i];
    if (is_removed ? !cfg.layers.removed_points : !cfg.layers.points) continue;
    const float x = data[4 * i], y = data[4 * i + 1], z = data[4 * i + 2];
    const float u = P(0, 0) * x + P(0, 1) * y + P(0, 2) * z + P(0, 3);
    const float v = P(1, 0) * x + P(1, 1) * y + P(1, 2) * z + P(1, 3);
    if (!(u >= 0.f && v >= 0.f && u < w && v < h)) continue;  // also drops NaN
    uint8_t& c = codes.at<uint8_t>(static_cast<int>(v), static_cast<int>(u));
    const uint8_t code = shading.code(z, is_removed);
    if (code > c) c = code;
  }
  for (int r = 0; r < img.rows; ++r) {
    const uint8_t* code = codes.ptr<uint8_t>(r);
    cv::Vec3b* px = img.ptr<cv::Vec3b>(r);
    for (int c = 0; c < img.cols; ++c)
      if (code[c]) px[c] = shading.colour(code[c]);
  }
  return counts;
}

Polygon project(const std::array<Eigen::Vector3d, 4>& corners, const ViewTransform::Projection& P) {
  Polygon out;
  for (const auto& c : corners) out.push_back(P * c.homogeneous());
  return out;
}

// The midpoint of the front edge (corners 0 and 3 are the front ones, see footprint()).
Eigen::Vector2d front(const Polygon& p) { return 0.5 * (p[0] + p[3]); }
Eigen::Vector2d centre(const Polygon& p) { return 0.25 * (p[0] + p[1] + p[2] + p[3]); }

void drawLidarBoxes(cv::Mat& img, const std::vector<Box>& boxes, const ViewTransform& view, const cv::Scalar& colour) {
  for (const Box& b : boxes) {
    const Polygon p = project(footprint(b.pose(), b.size), view.lidarToPixel());
    polyline(img, p, true, colour, 1);
    line(img, centre(p), front(p), colour, 1);
  }
}

void drawAssociations(cv::Mat& img, const RenderInput& in, const ViewTransform& view) {
  for (const AssociationMark& m : in.associations) {
    if (!m.predicted_lidar) continue;
    const cv::Scalar c = trackColour(m.track_id);
    const Eigen::Vector2d p = view.fromLidar(*m.predicted_lidar);
    if (m.detection_index >= 0 && m.detection_index < static_cast<int>(in.detections.size()))
      dashedLine(img, p, view.fromLidar(in.detections[m.detection_index].center), dimmed(c, 0.8), 1, 3, 3);
    line(img, p + Eigen::Vector2d(-3, -3), p + Eigen::Vector2d(3, 3), c, 1);
    line(img, p + Eigen::Vector2d(-3, 3), p + Eigen::Vector2d(3, -3), c, 1);
  }
}

void drawPath(cv::Mat& img, const std::vector<Eigen::Vector3d>& path, const ViewTransform& view,
              const cv::Scalar& colour, int thickness) {
  Polygon px;
  px.reserve(path.size());
  for (const auto& p : path) px.push_back(view.fromWorld(p));
  polyline(img, px, false, colour, thickness);
}

void drawTracks(cv::Mat& img, const RenderInput& in, const ViewTransform& view, const ViewConfig& cfg) {
  if (cfg.layers.track_trails)
    for (const TrackState& t : in.tracks) {
      std::vector<Eigen::Vector3d> trail = t.trail;
      trail.push_back(t.pose.translation());
      const cv::Scalar c = dimmed(trackColour(t.id), 0.7);
      drawPath(img, trail, view, c, 1);
      for (size_t i = 0; i + 1 < trail.size(); ++i)
        cv::circle(img, subpixel(view.fromWorld(trail[i])), 1 << kShift, c, cv::FILLED, cv::LINE_AA, kShift);
    }
  if (!cfg.layers.tracks) return;
  for (const TrackState& t : in.tracks) {
    const cv::Scalar c = trackColour(t.id);
    const Polygon p = project(footprint(t.pose, t.size), view.worldToPixel());
    if (t.is_dynamic) {
      fillTranslucent(img, p, c, 0.3);
      polyline(img, p, true, c, 2);
      const Eigen::Vector3d v(t.velocity.x(), t.velocity.y(), 0.0);
      if (v.norm() >= 0.3)
        arrow(img, centre(p), view.fromWorld(t.pose.translation() + cfg.velocity_arrow_s * v), c, 2);
    } else {
      dashedPolygon(img, p, c, 1, 5, 4);
    }
    line(img, centre(p), front(p), c, 1);
  }
  // Labels last, above every box.
  LabelPlacer labels;
  for (const TrackState& t : in.tracks) {
    const Polygon p = project(footprint(t.pose, t.size), view.worldToPixel());
    // Right of the box's top edge in the image, clear of its outline and (mostly) of its arrow.
    double right = p[0].x(), top = p[0].y();
    for (const auto& q : p) right = std::max(right, q.x()), top = std::min(top, q.y());
    const std::string s = t.is_dynamic ? strf("%d  %.1f m/s", t.id, t.velocity.head<2>().norm()) : strf("%d", t.id);
    labels.place(img, s, cv::Point(static_cast<int>(right) + 6, static_cast<int>(top) + 10), trackColour(t.id));
  }
}

void drawEgo(cv::Mat& img, const ViewTransform& view) {
  // A car-sized footprint around the sensor, heading forward.
  Pose T = Pose::Identity();
  T.translation() = Eigen::Vector3d(-0.3, 0, 0);
  const Polygon p = project(footprint(T, Eigen::Vector3d(4.4, 1.8, 0)), view.lidarToPixel());
  fillTranslucent(img, p, colour::kEgo, 0.3);
  polyline(img, p, true, colour::kEgo, 2);
  const Eigen::Vector2d f = front(p), c = centre(p);
  arrow(img, c, f + (f - c) * 0.6, colour::kEgo, 2);
}

double moduleTotal(const ModuleTiming& m) {
  double sum = 0;
  for (const auto& [name, ms] : m.stages) {
    if (name == "total") return ms;
    sum += ms;
  }
  return sum;
}

std::vector<TextLine> statusLines(const RenderInput& in, const PointCounts& pts) {
  std::vector<TextLine> lines;
  std::string title = strf("frame %06d    t %.2f s", in.frame, in.time_s);
  if (!in.slot_mode.empty()) title += "    [" + in.slot_mode + "]";
  lines.push_back({title, colour::kText, kTitleFont});
  if (in.ego_pose) {
    const Eigen::Vector3d t = in.ego_pose->translation();
    lines.push_back({strf("ego (%s)  x %.2f  y %.2f  z %.2f  yaw %.1f deg", in.ego_source.c_str(), t.x(), t.y(),
                            t.z(), yawOf(in.ego_pose->linear()) * 180.0 / M_PI),
                     colour::kText});
  } else {
    lines.push_back({"ego pose: none yet", colour::kWarning});
  }
  if (in.has_scan) {
    std::string s = strf("scan %d pts   kept %d   removed %d", pts.total, pts.total - pts.removed, pts.removed);
    if (in.has_odometry)
      s += in.odometry_filtered ? strf("   (odometry removed %d)", in.odometry_removed) : "   (odometry unfiltered)";
    lines.push_back({s, colour::kText});
  }
  int dynamic = 0;
  for (const TrackState& t : in.tracks) dynamic += t.is_dynamic;
  std::string objects;
  if (in.has_detections) objects += strf("detections %zu   ", in.detections.size());
  if (in.has_ground_truth) objects += strf("labels %zu   ", in.gt_boxes.size());
  if (in.has_tracks) objects += strf("tracks %zu (%d dynamic)", in.tracks.size(), dynamic);
  if (!objects.empty()) lines.push_back({objects, colour::kText});
  std::string missing;
  if (!in.has_scan) missing += " LIDAR_SCAN";
  if (!in.has_detections) missing += " DETECTIONS";
  if (!in.has_odometry) missing += " ODOMETRY";
  if (!in.has_associations) missing += " ASSOCIATIONS";
  if (!in.has_tracks) missing += " SLOT_STATE";
  if (!missing.empty()) lines.push_back({"missing:" + missing, colour::kWarning});
  return lines;
}

std::vector<TextLine> timingLines(const RenderInput& in) {
  std::vector<TextLine> lines;
  for (const ModuleTiming& m : in.timings) {
    const double total = moduleTotal(m);
    lines.push_back({strf(total < 10 ? "%-9s %7.2f ms" : "%-9s %7.1f ms", m.module.c_str(), total), colour::kText, kNormalFont});
    std::string detail;
    for (const auto& [name, ms] : m.stages) {
      if (name == "total") continue;
      const std::string item = strf("%s %.1f", name.c_str(), ms);
      if (detail.size() + item.size() > 44) {
        lines.push_back({"  " + detail, colour::kTextDim});
        detail.clear();
      }
      detail += (detail.empty() ? "" : "  ") + item;
    }
    if (!detail.empty()) lines.push_back({"  " + detail, colour::kTextDim});
  }
  return lines;
}

std::vector<LegendEntry> legendEntries(const Layers& l) {
  const PointShading shading(0.0, 1.0);
  auto sc = [](const cv::Vec3b& v) { return cv::Scalar(v[0], v[1], v[2]); };
  std::vector<LegendEntry> e;
  using S = LegendEntry::Swatch;
  if (l.points) e.push_back({S::Dots, sc(shading.colour(shading.code(0.3f, false))), "scan point (shade = height)", sc(shading.colour(shading.code(0.9f, false)))});
  if (l.removed_points) e.push_back({S::Dots, sc(shading.colour(shading.code(0.3f, true))), "removed as dynamic", sc(shading.colour(shading.code(0.9f, true)))});
  if (l.ground_truth) e.push_back({S::Box, colour::kGroundTruth, "ground-truth box"});
  if (l.detections) e.push_back({S::Box, colour::kDetection, "detection"});
  if (l.associations) e.push_back({S::Cross, trackColour(4), "predicted position (eq. 3)"});
  if (l.tracks) {
    e.push_back({S::FilledBox, trackColour(0), "dynamic track: id  speed"});
    e.push_back({S::DashedBox, trackColour(3), "static track"});
  }
  if (l.trajectories) {
    e.push_back({S::Line, colour::kSlot, "DL-SLOT"});
    e.push_back({S::Line, colour::kOdometry, "odometry"});
    e.push_back({S::Line, colour::kGroundTruth, "ground truth"});
  }
  return e;
}

}  // namespace

cv::Mat renderBev(const RenderInput& in, const ViewConfig& cfg) {
  cv::Mat img = solidImage(cfg.width, cfg.height, colour::kBackground);
  const ViewTransform view = ViewTransform::forFrame(cfg, in.ego_pose);
  const Layers& l = cfg.layers;

  if (l.grid) {
    if (cfg.mode == ViewConfig::Mode::Ego && cfg.heading_up)
      rangeRings(img, view.fromLidar(Eigen::Vector3d::Zero()), view.metresPerPixel());
    else
      worldGrid(img, view);
  }
  PointCounts pts;
  if (in.has_scan) pts = drawPoints(img, in, view, cfg);
  if (l.ground_truth) drawLidarBoxes(img, in.gt_boxes, view, colour::kGroundTruth);
  if (l.detections) drawLidarBoxes(img, in.detections, view, colour::kDetection);
  if (l.trajectories) {
    drawPath(img, in.gt_path, view, colour::kGroundTruth, 2);
    drawPath(img, in.odometry_path, view, colour::kOdometry, 2);
    drawPath(img, in.slot_path, view, colour::kSlot, 2);
  }
  if (l.associations) drawAssociations(img, in, view);
  drawTracks(img, in, view, cfg);
  drawEgo(img, view);

  if (l.text) {
    textPanel(img, statusLines(in, pts), cv::Point(12, 12));
    const std::vector<TextLine> timings = timingLines(in);
    if (!timings.empty()) textPanel(img, timings, cv::Point(img.cols - 12, 12), true);
  }
  if (l.legend) legend(img, legendEntries(l));
  if (l.scale_bar) scaleBar(img, view.metresPerPixel());
  return img;
}

std::vector<uchar> encodePng(const cv::Mat& img, int compression) {
  // Without parameters OpenCV takes its speed-tuned path (SUB filter, zlib level 1, RLE): about
  // half the time of an explicit level, which also turns on libpng's adaptive filters.
  const std::vector<int> params =
      compression < 0 ? std::vector<int>{} : std::vector<int>{cv::IMWRITE_PNG_COMPRESSION, compression};
  std::vector<uchar> png;
  if (!cv::imencode(".png", img, png, params)) throw std::runtime_error("cannot encode PNG");
  return png;
}

void writePng(const std::string& path, const cv::Mat& img, int compression) {
  const std::vector<uchar> png = encodePng(img, compression);
  // Written aside and renamed, so a viewer watching the directory never sees half an image.
  const std::string part = path + ".part";
  {
    std::ofstream out(part, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
    if (!out) throw std::runtime_error(path + ": cannot write PNG");
  }
  if (std::rename(part.c_str(), path.c_str()) != 0) throw std::runtime_error(path + ": cannot write PNG (rename failed)");
}

}  // namespace dlslot::renderer
