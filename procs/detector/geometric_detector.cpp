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

// Where a cluster lies in the range image: its columns (an interval that may pass the last
// column: a cluster behind the sensor wraps), its lowest and highest elevation (tan), its nearest
// and farthest range, its top (z).
struct Silhouette {
  int col_lo = 0, col_hi = -1;
  float min_tan = 1e9f, max_tan = -1e9f, near = 1e9f, far = 0.0f, top_z = -1e9f;

  void add(int column, int columns, float z, float range) {
    // Two candidate intervals, of the columns and of the columns turned half a circle; the
    // narrower one is the cluster's (an object spans far less than half a turn).
    lo_ = std::min(lo_, column), hi_ = std::max(hi_, column);
    const int turned = (column + columns / 2) % columns;
    turned_lo_ = std::min(turned_lo_, turned), turned_hi_ = std::max(turned_hi_, turned);
    min_tan = std::min(min_tan, z / range), max_tan = std::max(max_tan, z / range);
    near = std::min(near, range), far = std::max(far, range);
    top_z = std::max(top_z, z);
  }
  void close(int columns) {
    if (hi_ - lo_ <= turned_hi_ - turned_lo_) {
      col_lo = lo_, col_hi = hi_;
    } else {
      col_lo = turned_lo_ - columns / 2, col_hi = turned_hi_ - columns / 2;
      if (col_lo < 0) col_lo += columns, col_hi += columns;
    }
  }
  // Columns of [lo, hi] (wrapping like this interval) this interval shares.
  int overlap(const Silhouette& o, int n) const {
    int best = 0;
    for (int shift : {-n, 0, n})
      best = std::max(best, std::min(col_hi, o.col_hi + shift) - std::max(col_lo, o.col_lo + shift) + 1);
    return best;
  }

 private:
  int lo_ = 1 << 30, hi_ = -1, turned_lo_ = 1 << 30, turned_hi_ = -1;
};

// One cluster as the classifier and the occlusion test see it.
struct Measured {
  ClusterShape shape;
  Silhouette silhouette;
};

// Whether a nearer cluster covers the lower edge of cluster k: in front of it, spanning at least
// half of k's columns, reaching within about one beam up to k's lowest point's elevation, and
// lower than k's top (otherwise k is that car's own roof, seen beyond its body a beam later).
bool bottomHidden(const std::vector<Measured>& clusters, size_t k, int columns) {
  constexpr float kBeamTan = 0.012f;  // the HDL-64E's beams are 0.006-0.009 apart
  constexpr float kClear_m = 0.5f, kAbove_m = 0.3f;
  const Silhouette& c = clusters[k].silhouette;
  const int width = c.col_hi - c.col_lo + 1;
  for (size_t j = 0; j < clusters.size(); ++j) {
    const Silhouette& o = clusters[j].silhouette;
    if (j == k || o.far > c.near - kClear_m || o.top_z > c.top_z - kAbove_m) continue;
    if (o.max_tan < c.min_tan - kBeamTan || o.min_tan > c.min_tan) continue;
    if (2 * c.overlap(o, columns) >= width) return true;
  }
  return false;
}

Measured measureCluster(const PointCloud& scan, const ScanLayout& layout, const GroundModel& ground,
                        const std::vector<int>& members) {
  Measured out;
  ClusterShape& shape = out.shape;
  shape.num_points = static_cast<int>(members.size());
  shape.min_z = shape.max_z = scan(2, members[0]);
  shape.max_tan = -1e9;
  std::vector<Eigen::Vector2f> xy;
  xy.reserve(members.size());
  for (int i : members) {
    const float z = scan(2, i);
    shape.min_z = std::min<double>(shape.min_z, z);
    shape.max_z = std::max<double>(shape.max_z, z);
    shape.max_tan = std::max<double>(shape.max_tan, z / layout.range[i]);
    out.silhouette.add(layout.column[i], layout.columns, z, layout.range[i]);
    xy.emplace_back(scan(0, i), scan(1, i));
  }
  out.silhouette.close(layout.columns);
  shape.seen = fitRectangle(xy);
  shape.profile_step = profileStep(scan, members, shape.seen);
  shape.ground_z = ground.heightAt(static_cast<float>(shape.seen.center.x()), static_cast<float>(shape.seen.center.y()));
  // The ground under an object is the lowest of its cell and the object's own bottom (a
  // cluster that starts below the fitted ground stands in a dip).
  shape.ground_z = std::min(shape.ground_z, shape.min_z);
  return out;
}

// The points nearer than min_range_m are left out (the ego's own body), so a vehicle right beside
// the ego shows its side in two pieces, before and behind the sensor (highway seeds 9 and 10: a
// truck in the next lane missed for 11 and 16 frames). Two thin pieces on one line that passes
// through that blind circle, their near ends at the circle's chord, are one object.
void joinAcrossBlindCircle(const PointCloud& scan, const ScanLayout& layout, const GroundModel& ground,
                           double min_range_m, std::vector<std::vector<int>>& members, std::vector<Measured>& measured) {
  constexpr double kThin = 0.8, kOffLine = 0.3, kEndMargin = 0.8;
  const double kParallel = std::sin(5.0 * M_PI / 180.0);
  const auto thin = [&](const Rectangle& r) { return r.width < kThin && r.center.norm() < 3 * min_range_m + r.length; };
  for (size_t a = 0; a < measured.size(); ++a) {
    for (size_t b = a + 1; b < measured.size(); ++b) {
      const Rectangle &ra = measured[a].shape.seen, &rb = measured[b].shape.seen;
      if (!thin(ra) || !thin(rb)) continue;
      const Eigen::Vector2d u(std::cos(ra.yaw), std::sin(ra.yaw)), n(-u.y(), u.x());
      if (std::abs(u.x() * std::sin(rb.yaw) - u.y() * std::cos(rb.yaw)) > kParallel) continue;
      const double d = n.dot(ra.center);  // the line's distance from the sensor (signed)
      if (std::abs(d) >= min_range_m || std::abs(n.dot(rb.center) - d) > kOffLine) continue;
      // Along the line, from the foot of the perpendicular: the blind chord is [-half, half].
      const double half = std::sqrt(min_range_m * min_range_m - d * d);
      const double ta = u.dot(ra.center), tb = u.dot(rb.center);
      if (ta * tb >= 0) continue;  // both on one side of the sensor
      const double near_a = std::abs(ta) - 0.5 * ra.length, near_b = std::abs(tb) - 0.5 * rb.length;
      if (near_a > half + kEndMargin || near_b > half + kEndMargin) continue;
      members[a].insert(members[a].end(), members[b].begin(), members[b].end());
      members.erase(members.begin() + static_cast<long>(b));
      measured.erase(measured.begin() + static_cast<long>(b));
      measured[a] = measureCluster(scan, layout, ground, members[a]);
      b = a;  // the joined cluster may meet another piece
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
  std::vector<std::vector<int>> clusters =
      joinOverlappingClusters(scan, clusterRangeImage(scan, layout, obstacle, cfg.clustering),
                              cfg.clustering.join_margin_m, cfg.clustering.join_max_diagonal_m, cfg.clustering.min_points);
  out.timings.emplace_back("clustering", msSince(t));
  out.points_used = layout.num_used;
  out.obstacle_points = static_cast<int>(std::count(obstacle.begin(), obstacle.end(), 1));
  out.clusters = static_cast<int>(clusters.size());

  std::vector<Measured> measured;
  for (const std::vector<int>& members : clusters) measured.push_back(measureCluster(scan, layout, ground, members));
  joinAcrossBlindCircle(scan, layout, ground, cfg.window.min_range_m, clusters, measured);
  for (size_t k = 0; k < measured.size(); ++k) {
    const ClusterShape& shape = measured[k].shape;
    std::optional<Box> box = classifyCluster(shape, cfg.classes);
    // A vehicle seen over a nearer one (a van queueing behind a car; intersection seed 8): only its
    // top shows, so it seems to hang in the air like a sign. Its bottom is hidden, not raised, so it
    // is classified as standing on the ground, and kept when that makes it a vehicle (a person's
    // head and shoulders over a car are too little to tell from foliage: on the real slice such
    // "pedestrians" were all false).
    if (!box && shape.min_z - shape.ground_z > cfg.classes.max_bottom_m && bottomHidden(measured, k, layout.columns)) {
      ClusterShape standing = shape;
      standing.min_z = standing.ground_z;
      box = classifyCluster(standing, cfg.classes);
      if (box && !isVehicle(box->type)) box.reset();
    }
    if (box) {
      box->score = cfg.scores.apply(box->type, box->score);  // on PointRCNN's scale (score_calibration.hpp)
      out.boxes.push_back(std::move(*box));
      out.shapes.push_back(shape);
    }
  }
  demoteVehicleDuplicates(out.boxes);
  for (const Box& b : out.boxes) ++out.per_type[b.type];
  out.timings.emplace_back("boxes", msSince(t));
  return out;
}

}  // namespace dlslot::detector
