// KITTI results rows (kitti::projectToImage, kitti::resultRow, eval::writeKittiTracks): the 2-D box
// and alpha against hand computations and an independent projection, through a file and back.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>

#include "dlslot/kitti.hpp"
#include "export.hpp"

using namespace dlslot;
namespace fs = std::filesystem;

namespace {

// A camera whose axes are the lidar's turned (x right = -y_lidar, y down = -z_lidar, z ahead =
// x_lidar), no offsets: pixel = (600 + 700 X / Z, 180 + 700 Y / Z).
kitti::Calib simpleCalib() {
  kitti::Calib c;
  c.T_cam_velo.linear() << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  c.P[2] << 700, 0, 600, 0, 0, 700, 180, 0, 0, 0, 1, 0;
  return c;
}

// The calibration of KITTI tracking sequence 0000 (training/calib/0000.txt).
kitti::Calib kittiCalib() {
  kitti::Calib c;
  c.P[2] << 7.215377e+02, 0, 6.095593e+02, 4.485728e+01, 0, 7.215377e+02, 1.728540e+02, 2.163791e-01, 0, 0, 1,
      2.745884e-03;
  c.R_rect << 9.999239e-01, 9.837760e-03, -7.445048e-03, -9.869795e-03, 9.999421e-01, -4.278459e-03, 7.402527e-03,
      4.351614e-03, 9.999631e-01;
  c.T_cam_velo.matrix().topRows<3>() << 7.533745e-03, -9.999714e-01, -6.166020e-04, -4.069766e-03, 1.480249e-02,
      7.280733e-04, -9.998902e-01, -7.631618e-02, 9.998621e-01, 7.523790e-03, 1.480755e-02, -2.717806e-01;
  return c;
}

Box box(double x, double y, double z, double l, double w, double h, double yaw) {
  Box b;
  b.center << x, y, z;
  b.size << l, w, h;
  b.yaw = yaw;
  b.type = "Car";
  return b;
}

// Independent of kitti.cpp: what a reader of the row (the devkit, AB3DMOT) would compute from its
// 3-D fields: the corners as the devkit builds them (x = +-l/2, y = 0 or -h, z = +-w/2, rotated by
// roty(rotation_y), moved to the location), projected with P2, the pixel extremes clipped to the
// image. Valid for boxes wholly in front of the camera.
Eigen::Vector4d handProjection(const kitti::CameraBox& b, const kitti::Calib& calib, double width = 1242,
                               double height = 375) {
  const double xs[8] = {1, 1, -1, -1, 1, 1, -1, -1}, ys[8] = {0, 0, 0, 0, 1, 1, 1, 1}, zs[8] = {1, -1, -1, 1, 1, -1, -1, 1};
  const double c = std::cos(b.rotation_y), s = std::sin(b.rotation_y);
  double u0 = 1e9, v0 = 1e9, u1 = -1e9, v1 = -1e9;
  for (int i = 0; i < 8; ++i) {
    const double x = xs[i] * b.l / 2, y = -ys[i] * b.h, z = zs[i] * b.w / 2;
    const Eigen::Vector4d p(c * x + s * z + b.bottom_center.x(), y + b.bottom_center.y(),
                            -s * x + c * z + b.bottom_center.z(), 1.0);
    const Eigen::Vector3d q = calib.P[2] * p;
    EXPECT_GT(q.z(), 0.1);
    u0 = std::min(u0, q.x() / q.z());
    u1 = std::max(u1, q.x() / q.z());
    v0 = std::min(v0, q.y() / q.z());
    v1 = std::max(v1, q.y() / q.z());
  }
  const auto clip = [](double v, double hi) { return std::min(std::max(v, 0.0), hi); };
  return {clip(u0, width - 1), clip(v0, height - 1), clip(u1, width - 1), clip(v1, height - 1)};
}

}  // namespace

TEST(KittiResultRow, BoxStraightAheadHasTheHandComputedImageBoxAndAlpha) {
  // 4 m long along the lidar x axis, centred 10 m ahead: its faces are 8 and 12 m away, 1 m
  // either side and 1 m up and down, so the near face spans 600 +- 700 / 8 = 87.5 px.
  const auto r = kitti::resultRow(3, box(10, 0, 0, 4, 2, 2, 0), simpleCalib());
  ASSERT_TRUE(r);
  EXPECT_NEAR(r->bbox2d[0], 512.5, 1e-9);
  EXPECT_NEAR(r->bbox2d[1], 92.5, 1e-9);
  EXPECT_NEAR(r->bbox2d[2], 687.5, 1e-9);
  EXPECT_NEAR(r->bbox2d[3], 267.5, 1e-9);
  // Heading along the viewing ray away from the camera: rotation_y = -pi/2, seen straight on.
  EXPECT_NEAR(r->box.rotation_y, -M_PI / 2, 1e-12);
  EXPECT_NEAR(r->alpha, -M_PI / 2, 1e-12);
  EXPECT_EQ(r->frame, 3);
  EXPECT_EQ(r->type, "Car");
}

TEST(KittiResultRow, AlphaIsRotationYMinusTheDirectionOfTheObject) {
  // 45 deg to the right (camera x = z = 10), heading along lidar x: alpha = -pi/2 - pi/4.
  const auto r = kitti::resultRow(0, box(10, -10, 0, 4, 2, 2, 0), simpleCalib(), {2000, 375});
  ASSERT_TRUE(r);
  EXPECT_NEAR(r->alpha, -3 * M_PI / 4, 1e-12);
  // Facing the camera (yaw pi, rotation_y = pi/2) straight ahead: alpha = pi/2.
  const auto facing = kitti::resultRow(0, box(10, 0, 0, 4, 2, 2, M_PI), simpleCalib());
  ASSERT_TRUE(facing);
  EXPECT_NEAR(facing->alpha, M_PI / 2, 1e-12);
  // Crossing left to right 45 deg to the left: rotation_y 0, direction -pi/4, alpha pi/4.
  const auto left = kitti::resultRow(0, box(10, 10, 0, 4, 2, 2, -M_PI / 2), simpleCalib());
  ASSERT_TRUE(left);
  EXPECT_NEAR(left->box.rotation_y, 0.0, 1e-12);
  EXPECT_NEAR(left->alpha, M_PI / 4, 1e-12);
}

TEST(KittiResultRow, WrittenAndReadBackMatchesAnIndependentProjection) {
  const kitti::Calib calib = kittiCalib();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> ahead(6, 60), side(-8, 8), yaw(-M_PI, M_PI);
  std::vector<eval::FrameTracks> frames(20);
  for (int f = 0; f < 20; ++f) {
    frames[f].frame = f;
    for (int k = 0; k < 4; ++k) {
      Box b = box(ahead(rng), side(rng), -0.9, 4.2, 1.8, 1.6, yaw(rng));
      b.id = 10 * f + k;
      b.score = 0.25 * k;
      frames[f].boxes.push_back(b);
    }
  }
  const std::string path = (fs::temp_directory_path() / "dlslot_kitti_result_row.txt").string();
  const eval::ExportCount n = eval::writeKittiTracks(path, frames, calib);
  EXPECT_EQ(n.outside_image, 0);
  ASSERT_EQ(n.written, 80);
  const std::vector<kitti::LabelRow> rows = kitti::readTrackingLabels(path);
  ASSERT_EQ(rows.size(), 80u);
  int clipped = 0;
  for (const kitti::LabelRow& r : rows) {
    const Box& b = frames[r.frame].boxes[r.track_id % 10];
    ASSERT_EQ(r.track_id, b.id);
    EXPECT_NEAR(*r.score, b.score, 1e-6);
    // The row's 3-D fields (6 decimals in the file) projected again: the same box to a thousandth of a pixel.
    const Eigen::Vector4d expected = handProjection(r.box, calib);
    for (int i = 0; i < 4; ++i) EXPECT_NEAR(r.bbox2d[i], expected[i], 1e-3) << "row " << r.frame << " " << r.track_id;
    clipped += expected[0] == 0 || expected[2] == 1241;
    // alpha by its definition, from the row's own camera-frame box.
    const Eigen::Vector3d c = kitti::lidarToCamera(b, calib).bottom_center;
    EXPECT_NEAR(r.alpha, wrapAngle(r.box.rotation_y - std::atan2(c.x(), c.z())), 1e-5);
    EXPECT_GE(r.alpha, -M_PI - 1e-6);
    EXPECT_LE(r.alpha, M_PI + 1e-6);
  }
  EXPECT_GT(clipped, 0);  // some boxes reach past the image's sides, and are clipped there
  fs::remove(path);
}

TEST(KittiResultRow, BoxesTheCameraDoesNotSeeAreNotInTheImage) {
  const kitti::Calib calib = simpleCalib();
  EXPECT_FALSE(kitti::resultRow(0, box(-10, 0, 0, 4, 2, 2, 0), calib));  // behind
  EXPECT_FALSE(kitti::resultRow(0, box(1, 8, 0, 4, 2, 2, 0), calib));    // beside the car, partly behind
  EXPECT_FALSE(kitti::resultRow(0, box(10, 40, 0, 4, 2, 2, 0), calib));  // in front but far off to the left
  EXPECT_FALSE(kitti::resultRow(0, box(10, 0, 40, 4, 2, 2, 0), calib));  // high above the image
  // Far to the right in a 1242 px image, inside a 4000 px one.
  EXPECT_FALSE(kitti::resultRow(0, box(10, -12, 0, 4, 2, 2, 0), calib));
  EXPECT_TRUE(kitti::resultRow(0, box(10, -12, 0, 4, 2, 2, 0), calib, {4000, 375}));
}

TEST(KittiResultRow, ABoxAroundTheCameraCoversTheImageAndPartlyVisibleBoxesAreClipped) {
  const kitti::Calib calib = simpleCalib();
  // The camera inside the box: what is in front of it fills the whole image.
  const auto around = kitti::resultRow(0, box(0, 0, 0, 6, 3, 3, 0), calib);
  ASSERT_TRUE(around);
  EXPECT_EQ(around->bbox2d, Eigen::Vector4d(0, 0, 1241, 374));
  // Half behind the camera, 1..3 m to the right (camera X), 1 m up and down: the part in front is
  // cut at the near plane 0.1 m ahead. Its left edge is the near face's inner side 2 m ahead
  // (600 + 700 * 1 / 2 = 950); the cut at 0.1 m runs off the image to the right, top and bottom.
  const auto half = kitti::projectToImage(kitti::lidarToCamera(box(0, -2, 0, 4, 2, 2, 0), calib), calib);
  ASSERT_TRUE(half);
  EXPECT_NEAR(half->bbox2d[0], 950, 1e-9);
  EXPECT_EQ(half->bbox2d[2], 1241);
  EXPECT_EQ(half->bbox2d[1], 0);
  EXPECT_EQ(half->bbox2d[3], 374);
  EXPECT_NEAR(half->unclipped[0], 950, 1e-9);
  EXPECT_NEAR(half->unclipped[2], 600 + 700 * 3 / 0.1, 1e-6);
  EXPECT_NEAR(half->unclipped[1], 180 - 700 * 1 / 0.1, 1e-6);
}

TEST(KittiResultRow, ACalibrationWithoutP2CannotProject) {
  kitti::Calib calib = simpleCalib();
  calib.P[2].setZero();
  EXPECT_THROW(kitti::resultRow(0, box(10, 0, 0, 4, 2, 2, 0), calib), std::invalid_argument);
}
