#include "detector/geometric_detector.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <Eigen/Geometry>

#include "detector/ground_segmentation.hpp"
#include "detector/object_class.hpp"
#include "detector/range_image_clustering.hpp"
#include "detector/rectangle_fit.hpp"
#include "detector/scan_layout.hpp"

namespace dlslot::detector {

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point& t) {
  const Clock::time_point now = Clock::now();
  const double ms = std::chrono::duration<double, std::milli>(now - t).count();
  t = now;
  return ms;
}

// ClusterShape::profile_step: the highest point of each quarter of the rectangle's length.
double profileStep(const PointCloud& scan, const std::vector<int>& members, const Rectangle& r) {
  if (r.length < 1e-3) return 0.0;
  const Eigen::Vector2f u(static_cast<float>(std::cos(r.yaw)), static_cast<float>(std::sin(r.yaw)));
  const Eigen::Vector2f c = r.center.cast<float>();
  const float inv = static_cast<float>(1.0 / r.length);
  float top[4] = {-1e9f, -1e9f, -1e9f, -1e9f};
  for (int i : members) {
    const float t = (Eigen::Vector2f(scan(0, i), scan(1, i)) - c).dot(u) * inv + 0.5f;
    const int q = std::min(3, std::max(0, static_cast<int>(t * 4)));
    top[q] = std::max(top[q], scan(2, i));
  }
  float hi = -1e9f, lo = 1e9f;
  for (float z : top)
    if (z > -1e8f) hi = std::max(hi, z), lo = std::min(lo, z);
  return hi > lo ? hi - lo : 0.0;
}

bool isVehicle(const std::string& type) { return type == "Car" || type == "Van" || type == "Truck"; }

// A vehicle whose parts fell into two clusters (a far car's body below its cabin, a beam apart)
// gives two boxes, one inside the other: the less confident one whose centre lies in a more
// confident vehicle's footprint becomes Unknown (its points are still removed, it is not tracked).
void demoteVehicleDuplicates(std::vector<Box>& boxes) {
  std::vector<size_t> order;
  for (size_t i = 0; i < boxes.size(); ++i)
    if (isVehicle(boxes[i].type)) order.push_back(i);
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return boxes[a].score > boxes[b].score; });
  for (size_t k = 1; k < order.size(); ++k) {
    Box& d = boxes[order[k]];
    for (size_t j = 0; j < k; ++j) {
      const Box& o = boxes[order[j]];
      if (!isVehicle(o.type)) continue;
      const Eigen::Vector2d local = Eigen::Rotation2Dd(-o.yaw) * (d.center.head<2>() - o.center.head<2>());
      if (std::abs(local.x()) <= 0.5 * o.size.x() && std::abs(local.y()) <= 0.5 * o.size.y()) {
        d.type = kUnknownType;
        break;
      }
    }
  }
}

}  // namespace

DetectionResult detectObjects(const PointCloud& scan, const DetectorConfig& cfg) {
  DetectionResult out;
  auto t = Clock::now();
  const ScanLayout layout = layoutScan(scan, cfg);
  out.timings.emplace_back("layout", msSince(t));
  const GroundModel ground = fitGround(scan, layout, cfg.window, cfg.ground);
  const std::vector<uint8_t> obstacle = obstacleMask(scan, layout, ground, cfg.ground);
  out.timings.emplace_back("ground", msSince(t));
  const std::vector<std::vector<int>> clusters =
      joinOverlappingClusters(scan, clusterRangeImage(scan, layout, obstacle, cfg.clustering),
                              cfg.clustering.join_margin_m, cfg.clustering.join_max_diagonal_m, cfg.clustering.min_points);
  out.timings.emplace_back("clustering", msSince(t));
  out.points_used = layout.num_used;
  out.obstacle_points = static_cast<int>(std::count(obstacle.begin(), obstacle.end(), 1));
  out.clusters = static_cast<int>(clusters.size());

  std::vector<Eigen::Vector2f> xy;
  for (const std::vector<int>& members : clusters) {
    ClusterShape shape;
    shape.num_points = static_cast<int>(members.size());
    shape.min_z = shape.max_z = scan(2, members[0]);
    shape.max_tan = -1e9;
    xy.clear();
    for (int i : members) {
      const float z = scan(2, i);
      shape.min_z = std::min<double>(shape.min_z, z);
      shape.max_z = std::max<double>(shape.max_z, z);
      shape.max_tan = std::max<double>(shape.max_tan, z / layout.range[i]);
      xy.emplace_back(scan(0, i), scan(1, i));
    }
    shape.seen = fitRectangle(xy);
    shape.profile_step = profileStep(scan, members, shape.seen);
    shape.ground_z = ground.heightAt(static_cast<float>(shape.seen.center.x()), static_cast<float>(shape.seen.center.y()));
    // The ground under an object is the lowest of its cell and the object's own bottom (a
    // cluster that starts below the fitted ground stands in a dip).
    shape.ground_z = std::min(shape.ground_z, shape.min_z);
    if (std::optional<Box> box = classifyCluster(shape, cfg.classes)) {
      box->score = cfg.scores.apply(box->type, box->score);  // on PointRCNN's scale (score_calibration.hpp)
      ++out.per_type[box->type];
      out.boxes.push_back(std::move(*box));
      out.shapes.push_back(shape);
    }
  }
  demoteVehicleDuplicates(out.boxes);
  out.per_type.clear();
  for (const Box& b : out.boxes) ++out.per_type[b.type];
  out.timings.emplace_back("boxes", msSince(t));
  return out;
}

}  // namespace dlslot::detector
