// The backend's consistency test of the odometry factor (odometry_consistency.hpp): the
// chi-square quantile, the objects' consensus and the inflation on their own, and the window on
// a drive whose odometry loses 2 m a frame while parked cars and traffic say otherwise.
#include <gtest/gtest.h>

#include "backend/odometry_consistency.hpp"
#include "backend/sliding_window.hpp"
#include "backend_scene.hpp"

using namespace dlslot;
using namespace dlslot::backend;
using namespace dlslot::backend::test;

namespace {

TEST(OdometryCheck, ChiSquareQuantilesMatchTables) {
  // Tabulated values (e.g. NIST/SEMATECH e-Handbook, table of the chi-square distribution).
  EXPECT_NEAR(chiSquareQuantile(0.95, 1), 3.841, 1e-3);
  EXPECT_NEAR(chiSquareQuantile(0.99, 3), 11.345, 1e-3);
  EXPECT_NEAR(chiSquareQuantile(0.999, 3), 16.266, 1e-3);
  EXPECT_NEAR(chiSquareQuantile(0.99, 6), 16.812, 1e-3);
  EXPECT_NEAR(chiSquareQuantile(0.9999, 3), 21.108, 1e-3);
  EXPECT_THROW(chiSquareQuantile(1.0, 3), std::invalid_argument);
}

MotionEvidence evidence(int id, const Eigen::Vector3d& t, double sigma) {
  MotionEvidence e;
  e.track_id = id;
  e.translation = t;
  e.covariance = sigma * sigma * Eigen::Matrix3d::Identity();
  return e;
}

TEST(OdometryCheck, ConsensusIgnoresAnOutlierAndInflatesToTheGate) {
  // Three objects say 2 m along x, one (a wrong association) says 5 m sideways; the odometry
  // says 0 m with 1 cm.
  std::vector<MotionEvidence> ev = {evidence(1, {2.00, 0, 0}, 0.1), evidence(2, {2.05, 0.02, 0}, 0.1),
                                    evidence(3, {1.97, -0.03, 0}, 0.1), evidence(4, {0, 5, 0}, 0.1)};
  const Eigen::Matrix3d C = 1e-4 * Eigen::Matrix3d::Identity();
  ConsistencyOptions options;
  const OdometryCheck c = checkOdometry(Eigen::Vector3d::Zero(), C, ev, options);
  EXPECT_EQ(c.outcome, OdometryCheckOutcome::kDownweighted);
  EXPECT_EQ(c.evidence, 4);
  EXPECT_EQ(c.support, 3);
  EXPECT_NEAR(c.translation.x(), (2.00 + 2.05 + 1.97) / 3, 1e-9);
  EXPECT_NEAR(c.disagreement_m, c.translation.norm(), 1e-12);
  EXPECT_GT(c.chi2, 1000.0);
  // The inflation brings chi2 exactly to its expected value: d^T (k C + Sigma_objects)^-1 d = 3.
  const Eigen::Vector3d d = c.translation;
  EXPECT_NEAR(d.dot((c.inflation * C + c.covariance).inverse() * d), 3.0, 1e-6);
  EXPECT_FALSE(c.text().empty());

  // The same objects with an odometry that agrees: consistent, nothing inflated.
  const OdometryCheck ok = checkOdometry(Eigen::Vector3d(2.0, 0, 0), C, ev, options);
  EXPECT_EQ(ok.outcome, OdometryCheckOutcome::kConsistent);
  EXPECT_EQ(ok.inflation, 1.0);
  EXPECT_LT(ok.chi2, ok.gate);

  // Reporting only.
  options.downweight = false;
  EXPECT_EQ(checkOdometry(Eigen::Vector3d::Zero(), C, ev, options).outcome, OdometryCheckOutcome::kDisagreed);
  // One object alone may not overrule the odometry (a wrong association); two disagreeing
  // objects form no consensus of two either.
  options.downweight = true;
  EXPECT_EQ(checkOdometry(Eigen::Vector3d::Zero(), C, {ev[0]}, options).outcome, OdometryCheckOutcome::kUntested);
  EXPECT_EQ(checkOdometry(Eigen::Vector3d::Zero(), C, {ev[0], ev[3]}, options).outcome,
            OdometryCheckOutcome::kUntested);
}

// Driving along x at 20 m/s (2 m a frame) past parked cars on both sides, a car ahead in the next
// lane at the ego's speed and one overtaking at 25 m/s: a highway.
SimScene highwayScene() {
  SimScene s;
  s.ego = constantTwist(Pose::Identity(), 20.0, 0.0);
  s.odometry_noise << 0.01, 0.01, 0.005, 0.0005, 0.0005, 0.0005;
  s.box_noise << 0.1, 0.08, 0.05;
  s.yaw_noise = 0.02;
  for (int k = 0; k < 12; ++k) {
    SimObject o;
    o.id = k;
    const double x = 12.0 + 13.0 * k, y = k % 2 ? 6.0 : -7.0;
    o.pose = [x, y](double) { return planarPose(x, y, 0.05 * y); };
    o.visible = [x](int f) {
      const double ahead = x - 2.0 * f;
      return ahead > -20.0 && ahead < 40.0;
    };
    s.objects.push_back(o);
  }
  SimObject same, faster;
  same.id = 100;
  same.pose = constantTwist(planarPose(15, -3.5, 0), 20.0, 0.0);
  same.dynamic_guess = true;
  faster.id = 101;
  faster.pose = constantTwist(planarPose(-10, 3.5, 0), 25.0, 0.0);
  faster.dynamic_guess = true;
  s.objects.push_back(same);
  s.objects.push_back(faster);
  return s;
}

constexpr int kFrames = 40, kWrongFrom = 12;

// The odometry loses the ego's speed from frame kWrongFrom on: 0 m a frame instead of 2, with its
// usual 1 cm covariance (as the degenerate highway's did).
std::vector<BackendInput> wrongOdometry(std::vector<BackendInput> inputs) {
  Pose pose = Pose::Identity();
  for (BackendInput& in : inputs) {
    if (!in.odometry) continue;
    if (in.frame >= kWrongFrom) in.odometry->delta.translation().x() -= 2.0;
    pose = in.frame == 0 ? in.odometry->pose : pose * in.odometry->delta;
    in.odometry->pose = pose;
  }
  return inputs;
}

struct WindowRun {
  std::vector<BackendOutput> out;
  std::vector<Pose> ego;
};

WindowRun run(const std::vector<BackendInput>& inputs, bool check) {
  BackendConfig config;
  config.odometry_check.enabled = check;
  SlidingWindow window(config);
  WindowRun r;
  for (const BackendInput& in : inputs) {
    r.out.push_back(window.process(in));
    r.ego.push_back(r.out.back().ego_pose);
  }
  return r;
}

TEST(OdometryCheck, BackendFollowsTheLandmarksNotAnOdometryThatLostItsSpeed) {
  const SimScene scene = highwayScene();
  const std::vector<BackendInput> inputs = wrongOdometry(scene.generate(kFrames));

  // Without the test the odometry's 1 cm outweighs every box: the ego stands still.
  const WindowRun blind = run(inputs, false);
  const double blind_error =
      (blind.ego.back().translation() - scene.egoTruth(kFrames - 1).translation()).norm();
  EXPECT_GT(blind_error, 0.8 * 2.0 * (kFrames - kWrongFrom));

  const WindowRun checked = run(inputs, true);
  int downweighted = 0;
  double pull = 0;  // the bound below, accumulated
  for (int f = 0; f < kFrames; ++f) {
    const OdometryCheck& c = checked.out[f].odometry_check;
    if (f < kWrongFrom) {
      EXPECT_FALSE(c.disagreed()) << "frame " << f << ": " << c.text();
      continue;
    }
    // Every wrong frame is reported with its 2 m and down-weighted.
    EXPECT_EQ(c.outcome, OdometryCheckOutcome::kDownweighted) << "frame " << f;
    EXPECT_NEAR(c.disagreement_m, 2.0, 0.2) << "frame " << f;
    EXPECT_GT(c.chi2, c.gate);
    downweighted += c.outcome == OdometryCheckOutcome::kDownweighted;
    // The ego follows the objects. The inflated odometry still pulls the frame's motion toward
    // itself by at most 3 sigma^2 / d (the fusion of d with the objects' consensus of variance
    // sigma^2 along d at chi-square = 3): ~1.2 cm a frame here (sigma ~0.09 m, d = 2 m). The
    // position is then within that pull summed over the wrong frames plus the boxes' noise
    // (0.15 m, 1.5 sigma of a 0.1 m box), where the blind backend is 56 m off.
    const Eigen::Vector3d along = c.translation.normalized();  // ~x: the disagreement's direction
    const double variance = along.dot(c.covariance * along);
    const double frame_pull = c.target_chi2 * variance / c.disagreement_m;
    pull += frame_pull;
    EXPECT_LT((checked.ego[f].translation() - scene.egoTruth(f).translation()).norm(), 0.15 + pull) << "frame " << f;
    // Each frame's motion within 4 sigma of the objects' consensus (plus the pull) of the true 2 m.
    const Pose motion = checked.ego[f - 1].inverse() * checked.ego[f];
    const Pose truth = scene.egoTruth(f - 1).inverse() * scene.egoTruth(f);
    EXPECT_LT((motion.translation() - truth.translation()).norm(), 4 * std::sqrt(variance) + frame_pull) << "frame " << f;
  }
  EXPECT_LT(pull, 0.5);
  double worst = 0;
  for (int f = kWrongFrom; f < kFrames; ++f)
    worst = std::max(worst, (checked.ego[f].translation() - scene.egoTruth(f).translation()).norm());
  std::printf("ego error with the test: up to %.3f m (bound %.3f m); without it %.1f m\n", worst, 0.15 + pull, blind_error);
  EXPECT_EQ(downweighted, kFrames - kWrongFrom);
}

TEST(OdometryCheck, CorrectOdometryIsNeverFlaggedAndSolvedBitIdentically) {
  const SimScene scene = highwayScene();
  const std::vector<BackendInput> inputs = scene.generate(kFrames);
  const WindowRun checked = run(inputs, true);
  const WindowRun unchecked = run(inputs, false);
  int tested = 0;
  for (int f = 0; f < kFrames; ++f) {
    const OdometryCheck& c = checked.out[f].odometry_check;
    EXPECT_FALSE(c.disagreed()) << "frame " << f << ": " << c.text();
    tested += c.outcome == OdometryCheckOutcome::kConsistent;
    // A frame that passes is solved exactly as without the test.
    EXPECT_TRUE(checked.ego[f].matrix() == unchecked.ego[f].matrix()) << "frame " << f;
    ASSERT_EQ(checked.out[f].tracks.size(), unchecked.out[f].tracks.size());
    for (size_t k = 0; k < checked.out[f].tracks.size(); ++k)
      EXPECT_TRUE(checked.out[f].tracks[k].pose.matrix() == unchecked.out[f].tracks[k].pose.matrix());
  }
  // The parked cars are in the graph from their third sighting: most frames were tested.
  EXPECT_GT(tested, kFrames / 2);
}

}  // namespace
