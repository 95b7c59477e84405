// Per-object registration of one frame: 20 cars at 8-40 m (ray-cast box scans, as in
// tests/object_scan.hpp), each registered from a prediction 0.3 m and 2 deg off (goal: <= 3 ms a
// frame on one thread). A frame's cost is preparing each object's current points (which the next
// frame reuses as its previous ones) and registering: RegisterTwentyObjects. Beside it, the same
// with both clouds prepared for each registration, the preparation alone, and PCL's pieces for
// the same jobs (VoxelGrid + KdTreeFLANN + NormalEstimation; kd-tree nearest-point queries; GICP):
// why the registration has its own voxel-grid correspondences.
#include <benchmark/benchmark.h>

#include <pcl/features/normal_3d.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_types.h>
#include <pcl/registration/gicp.h>

#include <Eigen/Eigenvalues>
#include <random>

#include "backend/object_model.hpp"
#include "backend/object_registration.hpp"
#include "backend/side_ends.hpp"
#include "../tests/backend_scene.hpp"
#include "../tests/object_scan.hpp"

using namespace dlslot;
using namespace dlslot::backend;

namespace {

struct Pair {
  ObjectPoints previous, current;
  std::vector<ObjectPoints> earlier;  // the scans before `previous`, newest first (for a model)
  Pose prediction, truth;
  Eigen::Vector3d centroid;  // of the previous points: where a result's error is measured
  double range;
};

std::vector<Pair> makeFrame(int objects, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Pair> out;
  while (static_cast<int>(out.size()) < objects) {
    const double range = 24 + 16 * u(rng), bearing = u(rng) * M_PI;
    const Pose o0 = test::planarPose(range * std::cos(bearing), range * std::sin(bearing), u(rng) * M_PI, 0.75);
    const Pose truth = o0 * test::planarPose(1.5, 0, 0.03 * u(rng)) * o0.inverse();
    Pair p;
    p.previous = test::scanBox(o0, Eigen::Vector3d(4.5, 1.8, 1.5), Eigen::Vector3d(0, 0, 1.73), rng);
    p.current = test::scanBox(truth * o0, Eigen::Vector3d(4.5, 1.8, 1.5), Eigen::Vector3d(0, 0, 1.73), rng);
    // Their own random numbers: the other benchmarks' cars stay as they were.
    std::mt19937 earlier_rng(seed * 1000 + static_cast<unsigned>(out.size()));
    Pose o = o0;
    for (int k = 0; k < 3; ++k) {
      o = truth.inverse() * o;
      p.earlier.push_back(test::scanBox(o, Eigen::Vector3d(4.5, 1.8, 1.5), Eigen::Vector3d(0, 0, 1.73), earlier_rng));
    }
    // The prediction's error about the object (as the chain's is), not about the world origin:
    // 2 deg about a point 40 m away would move the car by 1.4 m.
    const Pose o1 = truth * o0;
    const Pose off = test::planarPose(0.3 * u(rng), 0.3 * u(rng), 0.035 * u(rng));
    p.prediction = o1 * off * o1.inverse() * truth;
    p.truth = truth;
    p.centroid.setZero();
    for (const Eigen::Vector3f& q : p.previous) p.centroid += q.cast<double>();
    p.centroid /= static_cast<double>(std::max<size_t>(1, p.previous.size()));
    p.range = range;
    out.push_back(std::move(p));
  }
  return out;
}

struct Errors {
  int measured = 0, iterations = 0, full = 0;
  double error2 = 0, full_error2 = 0;  // the measured results' error at the previous points' centroid (m^2)
  double measured_dirs_error2 = 0;     // of its horizontal directions said measured (sigma < 3 cm)
  void add(const RegistrationResult& r, const Pair& p) {
    iterations += r.iterations;
    if (!r.ok()) return;
    ++measured;
    const Eigen::Vector3d e = r.motion * p.centroid - p.truth * p.centroid;
    const double e2 = e.squaredNorm();
    error2 += e2;
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(r.information.topLeftCorner<2, 2>());
    double worst = 0;
    for (int k = 0; k < 2; ++k)
      if (es.eigenvalues()[k] > 1.0 / (0.03 * 0.03)) worst = std::max(worst, std::abs(es.eigenvectors().col(k).dot(e.head<2>())));
    measured_dirs_error2 += worst * worst;
    if (r.outcome == RegistrationOutcome::kMeasured) {
      full_error2 += e2;
      ++full;
    }
  }
  void report(benchmark::State& state, const std::vector<Pair>& frame) const {
    state.counters["measured"] = measured;
    state.counters["iterations_per_object"] = double(iterations) / frame.size();
    // Of every result (a partial one's unmeasured direction is the prediction's) and of the fully
    // measured ones.
    state.counters["rms_error_m"] = std::sqrt(error2 / std::max(1, measured));
    state.counters["full"] = full;
    state.counters["full_rms_error_m"] = std::sqrt(full_error2 / std::max(1, full));
    state.counters["measured_dirs_rms_error_m"] = std::sqrt(measured_dirs_error2 / std::max(1, measured));
    long points = 0;
    for (const Pair& p : frame) points += static_cast<long>(p.previous.size());
    state.counters["points_per_object"] = double(points) / frame.size();
  }
};

// A frame in the backend: each track's previous points were prepared in the previous frame; its
// current ones are prepared now (and kept for the next frame), then registered.
void registerFrame(benchmark::State& state, const RegistrationOptions& options) {
  const std::vector<Pair> frame = makeFrame(20, 1);
  std::vector<PreparedObject> previous;
  for (const Pair& p : frame) previous.emplace_back(p.previous, p.range, options);
  Errors errors;
  for (auto _ : state) {
    errors = Errors{};
    for (size_t i = 0; i < frame.size(); ++i) {
      const Pair& p = frame[i];
      const PreparedObject current(p.current, p.range, options);
      errors.add(registerObject(previous[i], current, p.prediction, options), p);
    }
  }
  errors.report(state, frame);
}

void BM_RegisterTwentyObjects(benchmark::State& state) { registerFrame(state, RegistrationOptions{}); }
BENCHMARK(BM_RegisterTwentyObjects)->Unit(benchmark::kMillisecond);

// All six directions fitted (planar off): the height drifts (full_rms_error_m).
void BM_RegisterTwentyObjectsSixDof(benchmark::State& state) {
  RegistrationOptions options;
  options.planar = false;
  registerFrame(state, options);
}
BENCHMARK(BM_RegisterTwentyObjectsSixDof)->Unit(benchmark::kMillisecond);

// The backend with registration_model_frames > 1: each track's model of its last scans (here 4,
// carried along by the true motions) was prepared in the previous frame (gridded only); the
// current points are prepared (with planes), registered to the model, taken into it, and the
// model prepared again for the next frame.
void BM_RegisterTwentyObjectsToModels(benchmark::State& state) {
  const std::vector<Pair> frame = makeFrame(20, 1);
  const RegistrationOptions options;
  RegistrationOptions model_options = options;
  model_options.max_target_points = options.max_model_points;
  std::vector<ObjectModel> models(frame.size());
  std::vector<PreparedObject> prepared;
  long model_points = 0;
  for (size_t i = 0; i < frame.size(); ++i) {
    const Pair& p = frame[i];
    for (int k = static_cast<int>(p.earlier.size()) - 1; k >= -1; --k) {
      const int f = static_cast<int>(p.earlier.size()) - 1 - k;
      models[i].update(k >= 0 ? p.earlier[static_cast<size_t>(k)] : p.previous, f, f > 0 ? std::optional<Pose>(p.truth) : std::nullopt,
                       p.range, options);
    }
    model_points += static_cast<long>(models[i].points().size());
    prepared.emplace_back(models[i].points(), p.range, model_options, false);
  }
  Errors errors;
  for (auto _ : state) {
    errors = Errors{};
    for (size_t i = 0; i < frame.size(); ++i) {
      const Pair& p = frame[i];
      const PreparedObject current(p.current, p.range, options);
      const RegistrationResult r = registerToModel(prepared[i], current, p.prediction, options);
      errors.add(r, p);
      ObjectModel next = models[i];
      next.update(p.current, models[i].frame() + 1,
                  r.outcome == RegistrationOutcome::kMeasured ? std::optional<Pose>(r.motion) : std::nullopt, p.range, options);
      benchmark::DoNotOptimize(PreparedObject(next.points(), p.range, model_options, false).points().data());
    }
  }
  errors.report(state, frame);
  state.counters["model_points_per_object"] = double(model_points) / frame.size();
}
BENCHMARK(BM_RegisterTwentyObjectsToModels)->Unit(benchmark::kMillisecond);

// Both clouds prepared for each registration (no reuse from the previous frame).
void BM_RegisterTwentyObjectsBothPrepared(benchmark::State& state) {
  const std::vector<Pair> frame = makeFrame(20, 1);
  const RegistrationOptions options;
  Errors errors;
  for (auto _ : state) {
    errors = Errors{};
    for (const Pair& p : frame) errors.add(registerObject(p.previous, p.current, p.prediction, p.range, options), p);
  }
  errors.report(state, frame);
}
BENCHMARK(BM_RegisterTwentyObjectsBothPrepared)->Unit(benchmark::kMillisecond);

// The preparation alone: thinning to one point per half voxel, the voxel grid, the planes of the
// (at most 80) source points.
void BM_PrepareTwentyObjects(benchmark::State& state) {
  const std::vector<Pair> frame = makeFrame(20, 1);
  const RegistrationOptions options;
  for (auto _ : state)
    for (const Pair& p : frame) benchmark::DoNotOptimize(PreparedObject(p.current, p.range, options).sourcePlanes().data());
}
BENCHMARK(BM_PrepareTwentyObjects)->Unit(benchmark::kMillisecond);

pcl::PointCloud<pcl::PointXYZ>::Ptr toPcl(const ObjectPoints& pts);

// The same preparation from PCL's pieces: VoxelGrid at the same half voxel, a KdTreeFLANN on its
// output, normals of 80 of its points from their 8 nearest neighbours.
void BM_PclPrepareTwentyObjects(benchmark::State& state) {
  const std::vector<Pair> frame = makeFrame(20, 1);
  const RegistrationOptions options;
  std::vector<pcl::PointCloud<pcl::PointXYZ>::Ptr> clouds;
  for (const Pair& p : frame) clouds.push_back(toPcl(p.current));
  for (auto _ : state)
    for (size_t i = 0; i < frame.size(); ++i) {
      const float leaf = static_cast<float>(0.5 * std::max(options.min_voxel, options.voxel_per_m * frame[i].range));
      auto thinned = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
      pcl::VoxelGrid<pcl::PointXYZ> grid;
      grid.setInputCloud(clouds[i]);
      grid.setLeafSize(leaf, leaf, leaf);
      grid.filter(*thinned);
      auto tree = std::make_shared<pcl::search::KdTree<pcl::PointXYZ>>();
      pcl::NormalEstimation<pcl::PointXYZ, pcl::Normal> ne;
      ne.setInputCloud(thinned);
      ne.setSearchMethod(tree);  // builds the kd-tree on the thinned points
      ne.setKSearch(options.plane_neighbours);
      auto indices = std::make_shared<pcl::Indices>();
      const size_t m = std::min<size_t>(thinned->size(), options.max_source_points);
      for (size_t k = 0; k < m; ++k) indices->push_back(static_cast<int>(k * thinned->size() / m));
      ne.setIndices(indices);
      pcl::PointCloud<pcl::Normal> normals;
      ne.compute(normals);
      benchmark::DoNotOptimize(normals.data());
    }
}
BENCHMARK(BM_PclPrepareTwentyObjects)->Unit(benchmark::kMillisecond);

// Nearest-point queries as the Gauss-Newton loop makes them (each object's source points at 8
// poses from the prediction to the truth): the voxel grid's against a KdTreeFLANN's on the same
// thinned points.
Pose between(const Pose& a, const Pose& b, double s) {
  Pose m = Pose::Identity();
  m.linear() = Eigen::Quaterniond(a.linear()).slerp(s, Eigen::Quaterniond(b.linear())).toRotationMatrix();
  m.translation() = (1 - s) * a.translation() + s * b.translation();
  return m;
}

std::vector<std::vector<Eigen::Vector3d>> nearestQueries(const std::vector<Pair>& frame, const std::vector<PreparedObject>& prev) {
  std::vector<std::vector<Eigen::Vector3d>> out(frame.size());
  for (size_t i = 0; i < frame.size(); ++i)
    for (int k = 0; k < 8; ++k) {
      const Pose M = between(frame[i].prediction, frame[i].truth, k / 7.0);
      for (const Eigen::Vector3d& p : prev[i].sourcePoints()) out[i].push_back(M * p);
    }
  return out;
}

void BM_GridNearestTwentyObjects(benchmark::State& state) {
  const std::vector<Pair> frame = makeFrame(20, 1);
  const RegistrationOptions options;
  std::vector<PreparedObject> prev, cur;
  for (const Pair& p : frame) {
    prev.emplace_back(p.previous, p.range, options);
    cur.emplace_back(p.current, p.range, options);
  }
  const auto queries = nearestQueries(frame, prev);
  for (auto _ : state)
    for (size_t i = 0; i < frame.size(); ++i)
      for (const Eigen::Vector3d& q : queries[i]) {
        double d2;
        benchmark::DoNotOptimize(cur[i].nearest(q, &d2));
      }
  state.counters["queries_per_object"] = double(queries[0].size());
}
BENCHMARK(BM_GridNearestTwentyObjects)->Unit(benchmark::kMillisecond);

void BM_PclNearestTwentyObjects(benchmark::State& state) {
  const std::vector<Pair> frame = makeFrame(20, 1);
  const RegistrationOptions options;
  std::vector<PreparedObject> prev;
  std::vector<pcl::KdTreeFLANN<pcl::PointXYZ>> trees(frame.size());
  for (size_t i = 0; i < frame.size(); ++i) {
    prev.emplace_back(frame[i].previous, frame[i].range, options);
    const PreparedObject cur(frame[i].current, frame[i].range, options);
    auto cloud = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
    for (const Eigen::Vector3d& p : cur.points()) cloud->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
    trees[i].setInputCloud(cloud);
  }
  const auto queries = nearestQueries(frame, prev);
  pcl::Indices index(1);
  std::vector<float> d2(1);
  for (auto _ : state)
    for (size_t i = 0; i < frame.size(); ++i)
      for (const Eigen::Vector3d& q : queries[i])
        benchmark::DoNotOptimize(trees[i].nearestKSearch(pcl::PointXYZ(q.x(), q.y(), q.z()), 1, index, d2));
}
BENCHMARK(BM_PclNearestTwentyObjects)->Unit(benchmark::kMillisecond);

pcl::PointCloud<pcl::PointXYZ>::Ptr toPcl(const ObjectPoints& pts) {
  auto c = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  for (const auto& p : pts) c->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  return c;
}

void BM_PclGicpTwentyObjects(benchmark::State& state) {
  const std::vector<Pair> frame = makeFrame(20, 1);
  for (auto _ : state) {
    for (const Pair& p : frame) {
      // Double precision, as our registration: PCL's float instantiation also trips GCC 12's
      // -Warray-bounds inside Eigen's SSE Umeyama (a false positive, but a printed warning).
      pcl::GeneralizedIterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ, double> gicp;
      gicp.setInputSource(toPcl(p.previous));
      gicp.setInputTarget(toPcl(p.current));
      gicp.setMaxCorrespondenceDistance(1.0);
      gicp.setMaximumIterations(12);
      pcl::PointCloud<pcl::PointXYZ> aligned;
      gicp.align(aligned, p.prediction.matrix());
      benchmark::DoNotOptimize(gicp.getFinalTransformation());
    }
  }
}
BENCHMARK(BM_PclGicpTwentyObjects)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace

// Which ends of 20 vehicles' sides a scan saw (side_ends.hpp): the scan's azimuth index (an
// atan2 per point) and each vehicle's test, on a scan of the HDL-64E's size (64 rings x 2000
// columns, 128 000 points) with 20 cars 15-75 m away.
void BM_EndsSeenOfTwentyObjects(benchmark::State& state) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> background(20.0, 80.0);
  const double step = 0.18 * M_PI / 180.0;
  PointCloud scan(4, 64 * 2000);
  Eigen::Index n = 0;
  for (int c = 0; c < 2000; ++c)
    for (int r = 0; r < 64; ++r) {
      const double a = -M_PI + (c + 0.5) * step, e = (-24.0 + 26.0 * r / 63.0) * M_PI / 180.0, range = background(rng);
      scan.col(n++) << range * std::cos(a), range * std::sin(a), range * std::tan(e), 0.0;
    }
  std::vector<Box> crops;
  std::vector<ObjectPoints> objects;
  for (int k = 0; k < 20; ++k) {
    const double a = 2.0 * M_PI * k / 20.0, range = 15.0 + 3.0 * k;
    Box crop;
    crop.center = Eigen::Vector3d(range * std::cos(a), range * std::sin(a), -1.0);
    crop.size = Eigen::Vector3d(4.5 + 1.0, 1.8 + 1.0, 1.6);
    crop.yaw = a + M_PI / 2;  // its side toward the sensor
    const ObjectPoints car = test::scanBox(crop.pose(), Eigen::Vector3d(4.5, 1.8, 1.5), Eigen::Vector3d::Zero(), rng, 0.01, false);
    objects.push_back(car);
    crops.push_back(crop);
  }
  std::vector<const ObjectPoints*> pointers;
  for (const ObjectPoints& o : objects) pointers.push_back(&o);
  int seen = 0;
  for (auto _ : state) {
    const AzimuthIndex index(scan, step, pointers);
    seen = 0;
    for (size_t k = 0; k < crops.size(); ++k) seen += endsSeen(index, objects[k], crops[k]).both();
    benchmark::DoNotOptimize(seen);
  }
  state.counters["both_seen"] = seen;
}
BENCHMARK(BM_EndsSeenOfTwentyObjects)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
