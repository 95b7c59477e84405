// The renderer's drawing core: pixels where a point, a box and a trajectory must (and must not)
// be, byte-identical output for the same input, frames with missing layers, the view config.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "bev_renderer.hpp"
#include "drawing.hpp"
#include "palette.hpp"
#include "render_config.hpp"
#include "summary_renderer.hpp"

namespace dlslot::renderer {
namespace {

// Channel-wise distance between a pixel and a colour.
int distance(const cv::Mat& img, int u, int v, const cv::Scalar& c) {
  const cv::Vec3b p = img.at<cv::Vec3b>(v, u);
  int d = 0;
  for (int i = 0; i < 3; ++i) d = std::max(d, std::abs(p[i] - static_cast<int>(c[i])));
  return d;
}
cv::Scalar scalar(const cv::Vec3b& v) { return cv::Scalar(v[0], v[1], v[2]); }

// 400 x 400 at 0.1 m/px, heading up: lidar (x, y) is pixel (200 - 10 y, 200 - 10 x).
ViewConfig bareView() {
  ViewConfig v;
  v.width = v.height = 400;
  v.metres_per_pixel = 0.1;
  v.layers = layersFromNames({"points", "removed_points", "detections", "tracks", "trajectories"}, "test");
  return v;
}

// A scan of three points, a detection around one of them, a dynamic track, a DL-SLOT path.
RenderInput knownFrame() {
  RenderInput in;
  in.frame = 7;
  in.time_s = 0.7;
  in.has_scan = true;
  in.scan.resize(4, 3);
  in.scan.col(0) << 5.0f, 0.0f, -1.0f, 0.5f;   // kept: pixel (200, 150)
  in.scan.col(1) << 0.0f, -9.5f, 0.5f, 0.5f;   // inside the detection: pixel (295, 200)
  in.scan.col(2) << -30.0f, 0.0f, 0.0f, 0.5f;  // outside the image
  in.has_detections = true;
  Box det;
  det.center = Eigen::Vector3d(0, -10, 0);
  det.size = Eigen::Vector3d(4, 2, 2);
  det.type = "Car";
  in.detections = {det};
  in.has_tracks = true;
  TrackState t;
  t.id = 3;
  t.type = "Car";
  t.pose = Pose::Identity();
  t.pose.translation() = Eigen::Vector3d(10, 10, 0);  // box: x 8..12, y 9..11 -> u 90..110, v 80..120
  t.size = Eigen::Vector3d(4, 2, 1.5);
  t.velocity = Eigen::Vector3d(5, 0, 0);
  t.is_dynamic = true;
  in.tracks = {t};
  in.ego_pose = Pose::Identity();
  in.ego_source = "DL-SLOT";
  for (int i = 0; i <= 10; ++i) in.slot_path.emplace_back(-15.0 + 1.5 * i, 0.0, 0.0);  // v 350 -> 200 at u 200
  return in;
}

TEST(RendererBev, PointsBoxAndTrajectoryWhereTheyMustBe) {
  const ViewConfig view = bareView();
  const cv::Mat img = renderBev(knownFrame(), view);
  ASSERT_EQ(img.cols, 400);
  ASSERT_EQ(img.rows, 400);
  ASSERT_EQ(img.type(), CV_8UC3);
  const PointShading shading(view.min_height_m, view.max_height_m);

  // Points: exact shaded colours, kept and removed in different ramps.
  EXPECT_EQ(distance(img, 200, 150, scalar(shading.colour(shading.code(-1.0f, false)))), 0);
  EXPECT_EQ(distance(img, 295, 200, scalar(shading.colour(shading.code(0.5f, true)))), 0);
  EXPECT_NE(shading.colour(shading.code(0.5f, true)), shading.colour(shading.code(0.5f, false)));
  // ... and nothing next to them.
  EXPECT_EQ(distance(img, 203, 150, colour::kBackground), 0);
  EXPECT_EQ(distance(img, 200, 160, colour::kBackground), 0);

  // The detection's outline (x -2..2, y -11..-9): its left edge at u = 310, v 180..220.
  EXPECT_LT(distance(img, 310, 190, colour::kDetection), 60);
  // The dynamic track: solid outline in its id colour, translucent fill inside, nothing outside.
  const cv::Scalar tc = trackColour(3);
  EXPECT_LT(distance(img, 90, 100, tc), 60);    // left edge (y = 11)
  EXPECT_LT(distance(img, 100, 120, tc), 60);   // bottom edge (x = 8)
  const cv::Vec3b inside = img.at<cv::Vec3b>(112, 95);
  EXPECT_GT(distance(img, 95, 112, colour::kBackground), 10) << inside;  // filled
  EXPECT_GT(distance(img, 95, 112, tc), 40) << inside;                    // but not opaque
  EXPECT_EQ(distance(img, 60, 100, colour::kBackground), 0);
  EXPECT_EQ(distance(img, 140, 100, colour::kBackground), 0);
  // Its velocity arrow (5 m/s for 1 s) runs up from the centre to x = 15: pixel (100, 50).
  EXPECT_LT(distance(img, 100, 60, tc), 60);

  // The DL-SLOT trajectory behind the ego, along u = 200; no odometry or ground-truth line.
  EXPECT_LT(distance(img, 200, 330, colour::kSlot), 40);
  EXPECT_LT(distance(img, 200, 300, colour::kSlot), 40);
  EXPECT_EQ(distance(img, 230, 330, colour::kBackground), 0);
  int other_lines = 0;
  for (int v = 0; v < img.rows; ++v)
    for (int u = 0; u < img.cols; ++u)
      other_lines += distance(img, u, v, colour::kOdometry) < 30 || distance(img, u, v, colour::kGroundTruth) < 30;
  EXPECT_EQ(other_lines, 0);
}

TEST(RendererBev, UnfilteredOdometryRemovesNothing) {
  // A-LOAM mode: the odometry ran on the raw scan, so no point is drawn as removed.
  RenderInput in = knownFrame();
  in.has_odometry = true;
  in.odometry_filtered = false;
  const ViewConfig view = bareView();
  const cv::Mat img = renderBev(in, view);
  const PointShading shading(view.min_height_m, view.max_height_m);
  EXPECT_EQ(distance(img, 295, 200, scalar(shading.colour(shading.code(0.5f, false)))), 0);
}

TEST(RendererBev, WorldViewPlacesLidarLayersAtTheEgoPose) {
  ViewConfig view = bareView();
  view.mode = ViewConfig::Mode::World;
  view.world_center = Eigen::Vector2d(100, 50);
  RenderInput in = knownFrame();
  Pose ego = Pose::Identity();
  ego.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  ego.translation() = Eigen::Vector3d(100, 50, 0);
  in.ego_pose = ego;
  in.tracks.clear();
  in.slot_path.clear();
  const cv::Mat img = renderBev(in, view);
  const PointShading shading(view.min_height_m, view.max_height_m);
  // Lidar (5, 0) facing world +y is world (100, 55): x right, y up -> pixel (200, 150).
  EXPECT_EQ(distance(img, 200, 150, scalar(shading.colour(shading.code(-1.0f, false)))), 0);
  // Lidar (0, -9.5) is world (109.5, 50) -> pixel (295, 200), removed.
  EXPECT_EQ(distance(img, 295, 200, scalar(shading.colour(shading.code(0.5f, true)))), 0);
}

std::vector<uchar> png(const cv::Mat& img) { return encodePng(img, RendererConfig().png_compression); }

TEST(RendererBev, SameInputGivesByteIdenticalPng) {
  RenderInput in = knownFrame();
  in.has_ground_truth = true;
  in.gt_boxes = in.detections;
  in.odometry_path = in.gt_path = in.slot_path;
  in.timings = {{"odometry", {{"features", 5.0}, {"total", 80.0}}}, {"backend", {{"total", 12.5}}}};
  in.associations = {{0, 3, true, Eigen::Vector3d(0.5, -9.5, 0)}};
  in.has_associations = true;
  const ViewConfig all;  // every layer, 1000 x 1000
  const std::vector<uchar> a = png(renderBev(in, all)), b = png(renderBev(in, all));
  ASSERT_FALSE(a.empty());
  EXPECT_TRUE(a == b);
  // Through the file writer too.
  const std::string dir = std::filesystem::temp_directory_path() / "renderer_bev_test_png";
  std::filesystem::remove_all(dir);
  writePng(dir + "_a.png", renderBev(in, all), -1);
  writePng(dir + "_b.png", renderBev(in, all), -1);
  std::ifstream fa(dir + "_a.png", std::ios::binary), fb(dir + "_b.png", std::ios::binary);
  const std::string sa((std::istreambuf_iterator<char>(fa)), {}), sb((std::istreambuf_iterator<char>(fb)), {});
  EXPECT_GT(sa.size(), 1000u);
  EXPECT_EQ(sa, sb);
  std::filesystem::remove(dir + "_a.png");
  std::filesystem::remove(dir + "_b.png");
  // A different input gives a different image.
  in.tracks[0].pose.translation().x() += 1.0;
  EXPECT_FALSE(png(renderBev(in, all)) == a);
}

TEST(RendererBev, FramesWithMissingLayersRender) {
  const ViewConfig all;
  RenderInput nothing;  // only a frame index: no scan, no pose, nothing
  nothing.frame = 3;
  cv::Mat img = renderBev(nothing, all);
  EXPECT_EQ(img.size(), cv::Size(1000, 1000));
  // The warning about missing inputs is drawn (warning colour in the text panel).
  int warning = 0;
  for (int v = 0; v < 150; ++v)
    for (int u = 0; u < 500; ++u) warning += distance(img, u, v, colour::kWarning) < 40;
  EXPECT_GT(warning, 20);

  RenderInput scan_only;
  scan_only.frame = 4;
  scan_only.has_scan = true;
  scan_only.scan = knownFrame().scan;
  EXPECT_NO_THROW(img = renderBev(scan_only, all));

  RenderInput tracks_without_pose = knownFrame();
  tracks_without_pose.ego_pose.reset();
  tracks_without_pose.has_scan = false;
  tracks_without_pose.scan.resize(4, 0);
  EXPECT_NO_THROW(img = renderBev(tracks_without_pose, all));

  // An empty scan, NaN points and a degenerate box do not break drawing either.
  RenderInput odd = knownFrame();
  odd.scan.col(2) << NAN, NAN, NAN, 0.f;
  odd.tracks[0].size = Eigen::Vector3d::Zero();
  EXPECT_NO_THROW(img = renderBev(odd, all));
}

TEST(RendererBev, SummaryShowsThePaths) {
  RunSummary run;
  run.first_frame = 0;
  run.last_frame = 99;
  run.frames_rendered = 100;
  for (int f = 0; f < 100; ++f) {
    run.gt_path[f] = Eigen::Vector3d(f, 0, 0);
    run.slot_path[f] = Eigen::Vector3d(f, 0.02 * f, 0);
    run.odometry_path[f] = Eigen::Vector3d(f, 0.2 * f, 0);
  }
  TrackPath car;
  car.id = 1;
  car.type = "Car";
  car.is_dynamic = true;
  for (int f = 0; f < 50; ++f) car.positions.emplace_back(f * 1.5, -10, 0);
  car.last_pose.translation() = car.positions.back();
  car.size = Eigen::Vector3d(4, 2, 1.5);
  run.tracks = {car};
  DensityMap map(0.2, -1.0);
  PointCloud wall(4, 200);
  for (int i = 0; i < 200; ++i) wall.col(i) << 0.5f * i, 15.0f, 0.0f, 0.f;
  map.add(wall, Pose::Identity());
  SummaryConfig cfg;
  const cv::Mat img = renderSummary(run, &map, cfg);
  ASSERT_EQ(img.size(), cv::Size(cfg.width, cfg.height));
  auto count = [&](const cv::Scalar& c) {
    int n = 0;
    for (int v = 0; v < img.rows; ++v)
      for (int u = 0; u < img.cols; ++u) n += distance(img, u, v, c) < 30;
    return n;
  };
  EXPECT_GT(count(colour::kSlot), 200);
  EXPECT_GT(count(colour::kOdometry), 200);
  EXPECT_GT(count(colour::kGroundTruth), 100);
  EXPECT_GT(count(trackColour(1)), 100);
  EXPECT_TRUE(png(img) == png(renderSummary(run, &map, cfg)));
  EXPECT_NO_THROW(renderSummary(RunSummary(), nullptr, cfg));  // an empty run
}

TEST(RendererBev, SummaryKeepsTheSceneInViewWhenAnEstimateDiverges) {
  RunSummary run;
  for (int f = 0; f < 100; ++f) {
    run.gt_path[f] = Eigen::Vector3d(f, 0, 0);
    run.slot_path[f] = Eigen::Vector3d(f, f < 50 ? 0.0 : 1e4 * (f - 49), 0);  // runs away after frame 49
  }
  const SummaryConfig cfg;
  const cv::Mat img = renderSummary(run, nullptr, cfg);
  int gt = 0, warning = 0;
  for (int v = 0; v < img.rows; ++v)
    for (int u = 0; u < img.cols; ++u) {
      gt += distance(img, u, v, colour::kGroundTruth) < 30;
      warning += v < 150 && distance(img, u, v, colour::kWarning) < 40;
    }
  // The 99 m ground truth still spans most of the 1600 px width (2 px thick) ...
  EXPECT_GT(gt, 1500);
  // ... and the text says DL-SLOT leaves the view.
  EXPECT_GT(warning, 50);
}

TEST(RendererConfig, ShippedConfigAndBadLayer) {
  ConfigSection root = loadConfig(std::string(DLSLOT_SOURCE_DIR) + "/config/dlslot.yaml");
  const RendererConfig cfg = readRendererConfig(root);
  EXPECT_EQ(cfg.view.width, 1000);
  EXPECT_GT(cfg.view.removal_margin_m, 0.0);
  EXPECT_TRUE(cfg.view.layers.tracks);
  EXPECT_THROW(layersFromNames({"points", "trakcs"}, "renderer.view.layers"), ConfigError);
  try {
    layersFromNames({"trakcs"}, "renderer.view.layers");
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("trakcs"), std::string::npos);
  }
}

}  // namespace
}  // namespace dlslot::renderer
