// The accumulated object model (object_model.hpp) on ray-cast scans of box-shaped cars with known
// motion: registering the current scan to the points of several scans where the previous scan
// alone gives too little, the model's bounds, and the box made to cover the points of a partly
// seen car.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <random>

#include "backend/object_model.hpp"
#include "backend/object_registration.hpp"
#include "backend_scene.hpp"
#include "object_scan.hpp"

using namespace dlslot;
using namespace dlslot::backend;
using dlslot::backend::test::planarPose;
using dlslot::backend::test::kCar;
using dlslot::backend::test::kSensor;
using dlslot::backend::test::scanBox;

namespace {

struct Outcomes {
  RegistrationResult pair, model;
};

// A car driving along `o(k)`, scanned at frames 0..n-1; the last frame registered to the scan
// before it alone and to the model of the earlier ones (built as the backend builds it: each
// scan registered to the model and carried along by the result), both from the same prediction.
// `hide(k, points)` may take points out of scan k (an occlusion).
template <class PoseOf, class Hide>
Outcomes lastFrame(PoseOf o, int n, const Pose& prediction_error, std::mt19937& rng, int model_frames, Hide hide) {
  RegistrationOptions options;
  options.model_frames = model_frames;
  std::vector<ObjectPoints> scans;
  for (int k = 0; k < n; ++k) scans.push_back(hide(k, scanBox(o(k), kCar, kSensor, rng)));
  ObjectModel model;
  Outcomes out;
  for (int k = 0; k < n; ++k) {
    const double range = o(k).translation().norm();
    std::optional<Pose> measured;
    if (k > 0) {
      const Pose truth = o(k) * o(k - 1).inverse();
      const Pose prediction = prediction_error * truth;
      RegistrationOptions model_options = options;
      model_options.max_target_points = options.max_model_points;
      const PreparedObject target(model.points(), range, model_options, false), source(scans[k], range, options);
      const RegistrationResult r = registerToModel(target, source, prediction, options);
      if (r.outcome == RegistrationOutcome::kMeasured) measured = r.motion;
      if (k == n - 1) {
        out.model = r;
        out.pair = registerObject(scans[k - 1], scans[k], prediction, range, options);
      }
    }
    model.update(scans[k], k, measured, range, options);
  }
  return out;
}

}  // namespace

TEST(ObjectModel, HoldsTheLastScansCarriedAlongByTheirMotion) {
  // A car seen in four scans, moving 1.2 m a frame and turning: with the true motions the model's
  // points all lie on the car where it is now; points older than model_frames scans are gone; a
  // scan without a motion starts it over; the cap keeps the newest.
  std::mt19937 rng(21);
  RegistrationOptions options;
  options.model_frames = 3;
  options.max_model_points = 100000;
  const auto o = [](int k) { return planarPose(14, -5, 0.4, 0.75) * planarPose(1.2 * k, 0, 0.03 * k); };
  ObjectModel model;
  std::vector<size_t> sizes;
  for (int k = 0; k < 4; ++k) {
    const ObjectPoints scan = scanBox(o(k), kCar, kSensor, rng);
    sizes.push_back(scan.size());
    model.update(scan, k, k > 0 ? std::optional<Pose>(o(k) * o(k - 1).inverse()) : std::nullopt, 15.0, options);
  }
  EXPECT_EQ(model.frame(), 3);
  EXPECT_EQ(model.scans(), 3);  // scans 1, 2, 3
  EXPECT_EQ(model.points().size(), sizes[1] + sizes[2] + sizes[3]);
  const Pose inv = o(3).inverse();
  for (const Eigen::Vector3f& p : model.points()) {
    const Eigen::Vector3d q = (inv * p.cast<double>()).cwiseAbs();
    // On the box's surface: inside it and within range noise of a face.
    ASSERT_LT((q - 0.5 * kCar).maxCoeff(), 0.05);
    ASSERT_LT((0.5 * kCar - q).minCoeff(), 0.05);
  }
  // No motion: this scan alone.
  const ObjectPoints scan = scanBox(o(4), kCar, kSensor, rng);
  model.update(scan, 4, std::nullopt, 15.0, options);
  EXPECT_EQ(model.points().size(), scan.size());
  EXPECT_EQ(model.scans(), 1);
  // A gap (frame 6 after 4) starts it over too, motion or not.
  model.update(scan, 6, Pose::Identity(), 15.0, options);
  EXPECT_EQ(model.scans(), 1);
  // Past the cap: thinned and cut, the newest scan first.
  options.max_model_points = 150;
  model.update(scanBox(o(7), kCar, kSensor, rng), 7, o(7) * o(6).inverse(), 15.0, options);
  EXPECT_LE(model.points().size(), 150u);
  EXPECT_EQ(model.scans(), 1);  // the cap took the newest scan's thinned points only
}

TEST(ObjectModel, TheTurnedRoundResultKeepsItsInformation) {
  // M^-1 with its information: a perturbation of M and the perturbation of M^-1 it makes have the
  // same Mahalanobis length (first order), and turning round twice gives back the same.
  std::mt19937 rng(23);
  std::normal_distribution<double> n(0.0, 1.0);
  RegistrationResult r;
  r.motion = planarPose(25, -7, 0.3, 0.2) * planarPose(1.4, 0.1, 0.05) * planarPose(25, -7, 0.3, 0.2).inverse();
  Matrix6 A;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) A(i, j) = n(rng);
  r.information = A.transpose() * A;
  const RegistrationResult inv = inverted(r);
  EXPECT_LT((inv.motion * r.motion).translation().norm(), 1e-9);
  for (int trial = 0; trial < 5; ++trial) {
    Vector6 d;
    for (int k = 0; k < 6; ++k) d[k] = 1e-5 * n(rng);
    const Vector6 d_inv = minus(plus(r.motion, d).inverse(), inv.motion);
    EXPECT_NEAR(d.dot(r.information * d), d_inv.dot(inv.information * d_inv), 1e-4 * d.dot(r.information * d));
  }
  EXPECT_LT((inverted(inv).information - r.information).norm(), 1e-6 * r.information.norm());
}

TEST(ObjectModel, RegistersTheNextScanToTheModel) {
  // The current scan registered to the model of the scans before it recovers the motion, from
  // the same poor prediction as the scan-to-scan registration: the measured directions to 2 cm.
  std::mt19937 rng(29);
  const auto o = [](int k) { return planarPose(16, 6, -0.5, 0.75) * planarPose(1.3 * k, 0, 0.02 * k); };
  int measured = 0;
  for (int trial = 0; trial < 4; ++trial) {
    const Outcomes r = lastFrame(o, 5, planarPose(0.2, -0.15, 0.02), rng, 5, [](int, ObjectPoints p) { return p; });
    ASSERT_TRUE(r.model.ok()) << toString(r.model.outcome);
    const Pose truth = o(4) * o(3).inverse();
    const Eigen::Vector2d e = (r.model.motion * o(3).translation() - truth * o(3).translation()).head<2>();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(r.model.information.topLeftCorner<2, 2>());
    for (int k = 0; k < 2; ++k) {
      if (es.eigenvalues()[k] > 1.0 / (0.03 * 0.03)) {
        EXPECT_LT(std::abs(es.eigenvectors().col(k).dot(e)), 0.02);
      }
    }
    measured += r.model.outcome == RegistrationOutcome::kMeasured;
  }
  EXPECT_GE(measured, 1);
}

// The model of a car over five scans (true motions), in the world frame of the last.
template <class PoseOf>
ObjectPoints modelOf(PoseOf o, std::mt19937& rng) {
  RegistrationOptions options;
  ObjectModel model;
  for (int k = 0; k < 5; ++k)
    model.update(scanBox(o(k), kCar, kSensor, rng), k, k > 0 ? std::optional<Pose>(o(k) * o(k - 1).inverse()) : std::nullopt,
                 o(k).translation().norm(), options);
  return model.points();
}

TEST(RefinedBox, ACarSeenFromBehindGetsItsRearAndWidthFromItsPoints) {
  // Driving ahead in the lane, 12-16 m: the scans see its rear (whole) and nothing of its sides
  // worth the name. The detector's box is 0.5 m too far ahead, 0.25 m to the right, 0.3 m short
  // and 0.1 m narrow (size noise).
  std::mt19937 rng(31);
  const auto o = [](int k) { return planarPose(12 + 1.0 * k, 0.3, 0.02, 0.75); };
  const ObjectPoints points = modelOf(o, rng);
  const Pose truth = o(4);
  const Pose box = truth * planarPose(0.5, -0.25, 0.0);
  const Eigen::Vector3d size(4.2, 1.7, 1.5);
  const RefinedBox r = refinedBox(box, size, points, kSensor, 30);
  const Eigen::Vector3d e = truth.inverse() * r.pose.translation();  // error in the car's axes
  // Width: seen end to end, the points' extent, centred.
  EXPECT_NEAR(r.size.y(), kCar.y(), 0.05);
  EXPECT_NEAR(e.y(), 0.0, 0.05);
  // Length: not seen; the box keeps its 4.2 m with its rear on the car's rear.
  EXPECT_DOUBLE_EQ(r.size.x(), size.x());
  EXPECT_NEAR(e.x() - 0.5 * r.size.x(), -0.5 * kCar.x(), 0.05);
  // The centre's error along the car, 0.5 m before: half the length's error now.
  EXPECT_NEAR(e.x(), 0.5 * (size.x() - kCar.x()), 0.05);
  EXPECT_DOUBLE_EQ(r.size.z(), size.z());
  EXPECT_NEAR(e.z(), 0.0, 1e-9);
}

TEST(RefinedBox, ACarSeenFromTheSideGetsItsLength) {
  // Passing on the left, its whole side in view: the length is the points' extent (the detector
  // said 3.9 m), the centre their middle; to within the model's thinning cell (one point per half
  // voxel, 0.125 m here: an end's cell keeps the newest point in it, not the outermost).
  std::mt19937 rng(37);
  const auto o = [](int k) { return planarPose(-2 + 1.0 * k, 6.5, 0.0, 0.75); };
  const ObjectPoints points = modelOf(o, rng);
  const Pose truth = o(4);
  const RefinedBox r = refinedBox(truth * planarPose(-0.4, 0.2, 0.0), Eigen::Vector3d(3.9, 1.8, 1.5), points, kSensor, 30);
  const Eigen::Vector3d e = truth.inverse() * r.pose.translation();
  EXPECT_NEAR(r.size.x(), kCar.x(), 0.15);
  EXPECT_NEAR(e.x(), 0.0, 0.08);
  // Its near side seen squarely: the box's near side on it.
  EXPECT_NEAR(e.y(), 0.0, 0.05);
}

TEST(RefinedBox, SeenAtAnAngleTheBoxOnlyMovesToHoldThePoints) {
  // Ahead and to the left at 40 deg: the sensor sees the rear and the right side at an angle,
  // and the points may stop short of the far ends. A box that holds them stays where it is; one
  // they stick out of moves just far enough.
  std::mt19937 rng(41);
  const auto o = [](int k) { return planarPose(10 + 1.0 * k, 9, 0.0, 0.75); };
  const ObjectPoints points = modelOf(o, rng);
  const Pose truth = o(4);
  const Eigen::Vector3d big(5.5, 2.6, 1.5);  // holds them wherever they are
  const RefinedBox held = refinedBox(truth, big, points, kSensor, 30);
  EXPECT_LT((held.pose.translation() - truth.translation()).norm(), 1e-9);
  EXPECT_EQ(held.size, big);
  // Moved 0.6 m forward: the rear's points stick out by 0.1 m plus the 0.5 m of slack; moved back.
  const RefinedBox moved = refinedBox(truth * planarPose(1.1, 0, 0), big, points, kSensor, 30);
  const Eigen::Vector3d e = truth.inverse() * moved.pose.translation();
  EXPECT_NEAR(e.x() - 0.5 * big.x(), -0.5 * kCar.x(), 0.05);
  // Too few points: the box as it was.
  const ObjectPoints few(points.begin(), points.begin() + 20);
  const RefinedBox same = refinedBox(truth * planarPose(1.1, 0, 0), big, few, kSensor, 30);
  EXPECT_LT((same.pose.translation() - (truth * planarPose(1.1, 0, 0)).translation()).norm(), 1e-9);
}

TEST(ObjectModel, MeasuredWhereTheScanBeforeGivesAPartialMeasurement) {
  // A car 50 m ahead, heading 57 deg to the left, pulling away: each scan sees its rear-right
  // corner, the side a little more from scan to scan. Registered from the scan before (its few
  // rings' planes, the source) the motion across the line of sight is not measured (partial);
  // registered to the model of the scans before, the current scan is the source: its planes, on
  // both faces it sees, all find the model's points (which hold every face the chain has seen),
  // and both directions are measured. (With the previous scan alone as the target the outcome is
  // the same here: on these ray-cast boxes what decides is which scan's planes are used; the
  // scans further back add counterparts for faces the previous scan missed.)
  const auto o = [](int k) { return planarPose(50 + 1.5 * k * std::cos(1.0), 9 + 1.5 * k * std::sin(1.0), 1.0, 0.75); };
  int pair_partial = 0, model_measured = 0;
  for (int trial = 0; trial < 10; ++trial) {
    std::mt19937 rng(100 + trial);
    const Outcomes r = lastFrame(o, 5, planarPose(0.15, -0.1, 0.01), rng, 5, [](int, ObjectPoints p) { return p; });
    pair_partial += r.pair.outcome == RegistrationOutcome::kPartial;
    if (r.model.outcome != RegistrationOutcome::kMeasured) continue;
    ++model_measured;
    const Pose truth = o(4) * o(3).inverse();
    EXPECT_LT((r.model.motion * o(3).translation() - truth * o(3).translation()).head<2>().norm(), 0.03) << trial;
  }
  EXPECT_GE(pair_partial, 8);
  EXPECT_GE(model_measured, 9);
}
