// Detector speed (goal: <= 15 ms mean per 123k-point scan, one thread) on the real KITTI scans
// of ../shared/data/kitti-tracking-0000-head when present (else on ray-cast street scenes), with
// the split per stage. BM_Cluster* compares the two ways to cluster the same obstacle points:
// the range-image neighbourhood the detector uses, and PCL's EuclideanClusterExtraction (k-d tree
// radius search) at the same base distance.
#include <benchmark/benchmark.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/extract_clusters.h>

#include <filesystem>
#include <map>

#include "../tests/detector_scene.hpp"
#include "detector/geometric_detector.hpp"
#include "detector/ground_segmentation.hpp"
#include "detector/range_image_clustering.hpp"
#include "detector/scan_layout.hpp"
#include "dlslot/kitti.hpp"
#include "dlslot/timing_stats.hpp"

using namespace dlslot;
using namespace dlslot::detector;

namespace {

const std::vector<PointCloud>& scans() {
  static const std::vector<PointCloud> all = [] {
    std::vector<PointCloud> out;
    const std::string root = std::string(DLSLOT_SOURCE_DIR) + "/../shared/data/kitti-tracking-0000-head";
    if (std::filesystem::exists(root + "/training/velodyne/0000")) {
      const kitti::SequenceReader reader(root, "0000");
      for (int i = 0; i < reader.size(); ++i) out.push_back(reader.read(i).scan);
      return out;
    }
    for (int k = 0; k < 5; ++k) {
      test::DetectorScene s;
      for (int c = 0; c < 6; ++c) s.car(6.0 + 5.5 * c + k, -4.5, 0.0, 4.2, 1.75, 1.5);
      s.place("Pedestrian", 9.0 + k, 3.0, 0.0, 0.6, 0.5, 1.7);
      s.place("Wall", 20.0, 9.0, 0.0, 40.0, 0.3, 3.0);
      out.push_back(s.scan());
    }
    return out;
  }();
  return all;
}

// One iteration = one scan through detectObjects.
void BM_DetectorScan(benchmark::State& state) {
  const DetectorConfig cfg;
  std::map<std::string, TimingStats> stages;
  TimingStats total;
  double points = 0, boxes = 0;
  size_t i = 0;
  for (auto _ : state) {
    const PointCloud& scan = scans()[i++ % scans().size()];
    const auto tic = std::chrono::steady_clock::now();
    const DetectionResult r = detectObjects(scan, cfg);
    total.add(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - tic).count());
    for (const auto& [name, ms] : r.timings) stages[name].add(ms);
    points += scan.cols();
    boxes += r.boxes.size();
  }
  for (const auto& [name, s] : stages) state.counters[name + "_ms"] = s.mean();
  state.counters["scan_mean_ms"] = total.mean();
  state.counters["scan_p95_ms"] = total.percentile(95);
  state.counters["points_per_scan"] = points / total.count();
  state.counters["boxes_per_scan"] = boxes / total.count();
}
BENCHMARK(BM_DetectorScan)->Unit(benchmark::kMillisecond)->Iterations(90)->UseRealTime();

// The obstacle points of each scan, for the clustering comparison.
struct Obstacles {
  ScanLayout layout;
  std::vector<uint8_t> mask;
};
const std::vector<Obstacles>& obstacles() {
  static const std::vector<Obstacles> all = [] {
    const DetectorConfig cfg;
    std::vector<Obstacles> out;
    for (const PointCloud& s : scans()) {
      Obstacles o;
      o.layout = layoutScan(s, cfg);
      o.mask = obstacleMask(s, o.layout, fitGround(s, o.layout, cfg.window, cfg.ground), cfg.ground);
      out.push_back(std::move(o));
    }
    return out;
  }();
  return all;
}

void BM_ClusterRangeImage(benchmark::State& state) {
  const DetectorConfig cfg;
  size_t i = 0;
  double clusters = 0;
  for (auto _ : state) {
    const size_t k = i++ % scans().size();
    const auto c = clusterRangeImage(scans()[k], obstacles()[k].layout, obstacles()[k].mask, cfg.clustering);
    clusters += c.size();
  }
  state.counters["clusters"] = clusters / state.iterations();
}
BENCHMARK(BM_ClusterRangeImage)->Unit(benchmark::kMillisecond)->Iterations(30)->UseRealTime();

// PCL's Euclidean clustering of the same points at the range image's base distance (the k-d tree
// is built per scan, as it would have to be).
void BM_ClusterPclEuclidean(benchmark::State& state) {
  const DetectorConfig cfg;
  size_t i = 0;
  double clusters = 0;
  for (auto _ : state) {
    const size_t k = i++ % scans().size();
    const PointCloud& s = scans()[k];
    pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
    for (int p = 0; p < s.cols(); ++p)
      if (obstacles()[k].mask[p]) cloud->push_back(pcl::PointXYZ(s(0, p), s(1, p), s(2, p)));
    pcl::search::KdTree<pcl::PointXYZ>::Ptr tree(new pcl::search::KdTree<pcl::PointXYZ>);
    tree->setInputCloud(cloud);
    pcl::EuclideanClusterExtraction<pcl::PointXYZ> ec;
    ec.setClusterTolerance(cfg.clustering.distance_m);
    ec.setMinClusterSize(cfg.clustering.min_points);
    ec.setSearchMethod(tree);
    ec.setInputCloud(cloud);
    std::vector<pcl::PointIndices> out;
    ec.extract(out);
    clusters += out.size();
  }
  state.counters["clusters"] = clusters / state.iterations();
}
BENCHMARK(BM_ClusterPclEuclidean)->Unit(benchmark::kMillisecond)->Iterations(10)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
