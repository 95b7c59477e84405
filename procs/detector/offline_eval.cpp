#include "detector/offline_eval.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <stdexcept>

#include "detector/geometric_detector.hpp"
#include "detector/object_class.hpp"
#include "dlslot/kitti.hpp"

namespace dlslot::detector {

namespace {

// Area of the intersection of two image boxes (left top right bottom).
double overlap(const Eigen::Vector4d& a, const Eigen::Vector4d& b) {
  const double w = std::min(a[2], b[2]) - std::max(a[0], b[0]), h = std::min(a[3], b[3]) - std::max(a[1], b[1]);
  return w > 0 && h > 0 ? w * h : 0.0;
}

}  // namespace

OfflineResult runOffline(const OfflineOptions& opt, const DetectorConfig& cfg) {
  if (opt.sequence.empty()) throw std::invalid_argument("--sequence SSSS is required with --kitti");
  const kitti::SequenceReader reader(opt.root, opt.sequence);
  if (!reader.hasScans()) throw std::invalid_argument("sequence " + opt.sequence + " of " + opt.root + " has no scans");
  OfflineResult r;
  r.classes = defaultEvalClasses();
  r.counts.assign(r.classes.size(), {});
  r.has_labels = reader.hasLabels();
  const kitti::Calib& calib = reader.calib();
  // DontCare image regions per frame (their 3-D boxes are placeholders in KITTI's labels).
  std::map<int, std::vector<Eigen::Vector4d>> dontcare;
  if (opt.camera_view && !reader.paths().labels.empty())
    for (const kitti::LabelRow& row : kitti::readTrackingLabels(reader.paths().labels))
      if (row.type == "DontCare") dontcare[row.frame].push_back(row.bbox2d);
  const int n = opt.frames > 0 ? std::min(opt.frames, reader.size()) : reader.size();
  std::vector<kitti::LabelRow> rows;
  for (int i = 0; i < n; ++i) {
    const Frame frame = reader.read(i);
    const auto tic = std::chrono::steady_clock::now();
    const DetectionResult det = detectObjects(frame.scan, cfg);
    r.detect_ms.add(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - tic).count());
    r.boxes += static_cast<int>(det.boxes.size());
    std::vector<Box> scored;
    std::vector<Eigen::Vector4d> image_box;
    for (const Box& b : det.boxes) {
      if (b.type == kUnknownType) ++r.unknown_boxes;
      const std::optional<kitti::LabelRow> in_view = kitti::resultRow(i, b, calib);
      if (!opt.write_detections.empty()) rows.push_back(in_view ? *in_view : kitti::unprojectedRow(i, b, calib));
      if (opt.camera_view && !in_view) continue;
      scored.push_back(b);
      image_box.push_back(in_view ? in_view->bbox2d : Eigen::Vector4d::Zero());
    }
    const std::vector<Eigen::Vector4d>& dc = dontcare[i];
    auto ignore = [&](const Box& b) {
      const size_t k = static_cast<size_t>(&b - scored.data());
      const Eigen::Vector4d& box = image_box[k];
      const double area = (box[2] - box[0]) * (box[3] - box[1]);
      for (const Eigen::Vector4d& d : dc)
        if (area > 0 && overlap(box, d) >= 0.5 * area) return true;
      return false;
    };
    for (size_t c = 0; c < r.classes.size(); ++c)
      r.counts[c].add(matchFrame(frame.labels, scored, r.classes[c], opt.eval,
                                 opt.camera_view ? std::function<bool(const Box&)>(ignore) : nullptr));
    ++r.frames;
  }
  if (!opt.write_detections.empty()) kitti::writeTrackingLabels(opt.write_detections, rows);
  return r;
}

std::string formatResult(const OfflineResult& r, const OfflineOptions& opt) {
  std::string out;
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "sequence %s, %d frames, %d boxes (%d unknown); matched within %.1f m bird's-eye centre distance, "
                "labels and detections within %.0f m%s\n",
                opt.sequence.c_str(), r.frames, r.boxes, r.unknown_boxes, opt.eval.max_distance_m, opt.eval.max_range_m,
                opt.camera_view ? ", detections in camera 2's image only, DontCare regions ignored" : ", all around");
  out += buf;
  if (r.has_labels) {
    out += "class       labels  detections  matched  recall  precision\n";
    for (size_t c = 0; c < r.classes.size(); ++c) {
      const MatchCounts& m = r.counts[c];
      std::snprintf(buf, sizeof buf, "%-10s %7d %11d %8d  %6.3f  %9.3f\n", r.classes[c].name.c_str(), m.labels,
                    m.detections, m.matched, m.recall(), m.precision());
      out += buf;
    }
  } else {
    out += "no labels: nothing to evaluate\n";
  }
  std::snprintf(buf, sizeof buf, "detector time per scan: %.2f ms mean, %.2f ms p95, %.2f ms max\n", r.detect_ms.mean(),
                r.detect_ms.percentile(95), r.detect_ms.max());
  out += buf;
  return out;
}

}  // namespace dlslot::detector
