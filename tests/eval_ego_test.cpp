// Ego-motion metrics of the evaluator against hand-computed answers.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "dlslot/input_error.hpp"
#include "ego_metrics.hpp"
#include "evaluation.hpp"
#include "trajectory.hpp"

using namespace dlslot;
using namespace dlslot::eval;

namespace {

Pose poseXYZYaw(double x, double y, double z, double yaw) {
  Pose T = Pose::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() << x, y, z;
  return T;
}

// A gently curving drive: n frames, about 1 m apart.
Trajectory curvedDrive(int n) {
  Trajectory t;
  double x = 0, y = 0, yaw = 0;
  for (int i = 0; i < n; ++i) {
    t.add(i, 0.1 * i, poseXYZYaw(x, y, 0.01 * std::sin(0.05 * i), yaw));
    const double turn = 0.02 * std::sin(0.03 * i);
    yaw += turn;
    x += std::cos(yaw);
    y += std::sin(yaw);
  }
  return t;
}

// n frames along +x, `step` metres apart.
Trajectory straightLine(int n, double step) {
  Trajectory t;
  for (int i = 0; i < n; ++i) t.add(i, 0.1 * i, poseXYZYaw(step * i, 0, 0, 0));
  return t;
}

std::filesystem::path tempDir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("dlslot_eval_ego_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace

TEST(EvalEgo, IdenticalTrajectoriesGiveZeroEverywhere) {
  const Trajectory gt = curvedDrive(1000);
  const EgoMetrics m = evaluateEgo(gt, gt);
  EXPECT_EQ(m.frames, 1000);
  EXPECT_NEAR(*m.ate_rmse_m, 0.0, 1e-9);
  EXPECT_NEAR(*m.ate_unaligned_rmse_m, 0.0, 1e-12);
  EXPECT_NEAR(*m.rpe1_t_m, 0.0, 1e-12);
  EXPECT_NEAR(*m.rpe1_r_deg, 0.0, 1e-12);
  EXPECT_NEAR(*m.rpe10_t_m, 0.0, 1e-12);
  EXPECT_NEAR(*m.t_rel_pct, 0.0, 1e-9);
  EXPECT_NEAR(*m.r_rel_deg_per_100m, 0.0, 1e-12);
  EXPECT_NEAR(*m.t_rel_short_pct, 0.0, 1e-9);
  EXPECT_NEAR(*m.r_rel_short_deg_per_100m, 0.0, 1e-12);
}

TEST(EvalEgo, ConstantOffsetHasKnownAteBeforeAlignmentAndZeroAfter) {
  const Trajectory gt = curvedDrive(200);
  Trajectory est = gt;
  for (Pose& T : est.poses) T.translation() += Eigen::Vector3d(1, 2, 2);  // |offset| = 3 m
  EXPECT_NEAR(ateRmse(est, gt, false), 3.0, 1e-12);
  EXPECT_NEAR(ateRmse(est, gt, true), 0.0, 1e-9);
  // A rigid offset does not change relative motion.
  const EgoMetrics m = evaluateEgo(est, gt);
  EXPECT_NEAR(*m.rpe1_t_m, 0.0, 1e-9);
  EXPECT_NEAR(*m.rpe10_t_m, 0.0, 1e-9);
}

TEST(EvalEgo, UmeyamaRecoversAKnownRigidTransform) {
  const Trajectory gt = curvedDrive(100);
  Pose A = poseXYZYaw(5, -3, 1, 0.7);
  A.linear() = A.linear() * Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitX()).toRotationMatrix();
  std::vector<Eigen::Vector3d> est, truth;
  for (const Pose& T : gt.poses) {
    truth.push_back(T.translation());
    est.push_back(A.inverse() * T.translation());
  }
  const Pose found = alignUmeyama(est, truth);
  EXPECT_TRUE(found.isApprox(A, 1e-9)) << found.matrix() << "\nexpected\n" << A.matrix();
}

TEST(EvalEgo, RelativePoseErrorOfAStretchedPath) {
  // Each estimated step is 1.1 m instead of 1 m: 0.1 m error over one frame, 1 m over ten.
  const Trajectory gt = straightLine(50, 1.0), est = straightLine(50, 1.1);
  const auto r1 = relativePoseError(est, gt, 1), r10 = relativePoseError(est, gt, 10);
  ASSERT_TRUE(r1 && r10);
  EXPECT_NEAR(r1->t_rmse_m, 0.1, 1e-12);
  EXPECT_EQ(r1->pairs, 49);
  EXPECT_NEAR(r10->t_rmse_m, 1.0, 1e-12);
  EXPECT_EQ(r10->pairs, 40);
  EXPECT_FALSE(relativePoseError(est, gt, 50));  // no pair 50 frames apart
  // Stamps 0.1 s apart: 1.1 m a scan against 1 m is 1 m/s too fast, over any span.
  ASSERT_TRUE(r1->velocity_rmse_mps && r10->velocity_rmse_mps);
  EXPECT_NEAR(*r1->velocity_rmse_mps, 1.0, 1e-9);
  EXPECT_NEAR(*r10->velocity_rmse_mps, 1.0, 1e-9);
  EXPECT_NEAR(*evaluateEgo(est, gt).velocity_rmse_mps, 1.0, 1e-9);
}

TEST(EvalEgo, RelativePoseErrorPairsFramesByIndexAcrossGaps) {
  Trajectory gt = straightLine(20, 1.0), est = straightLine(20, 1.1);
  // Drop frame 5 from both: the pairs (4,5) and (5,6) disappear, (4,6) is 2 frames apart.
  for (Trajectory* t : {&gt, &est}) {
    t->frames.erase(t->frames.begin() + 5);
    t->stamps.erase(t->stamps.begin() + 5);
    t->poses.erase(t->poses.begin() + 5);
  }
  EXPECT_EQ(relativePoseError(est, gt, 1)->pairs, 17);
}

TEST(EvalEgo, ScaleDriftGivesTheDevkitsTranslationError) {
  // 1 % scale drift on a straight 999 m line with 1 m frames. The devkit's segment of length L
  // ends at the first frame more than L metres on, i.e. L + 1 frames later, so each segment's
  // error is 0.01 (L + 1) / L; t_rel is the mean over all segments starting every 10 frames.
  const int n = 1000;
  const Trajectory gt = straightLine(n, 1.0), est = straightLine(n, 1.01);
  const auto expected = [&](const std::vector<double>& lengths) {
    double sum = 0;
    int count = 0;
    for (int first = 0; first < n; first += 10)
      for (double L : lengths)
        if (first + L + 1 <= n - 1) {
          sum += 0.01 * (L + 1) / L;
          ++count;
        }
    return 100.0 * sum / count;
  };
  const EgoMetrics m = evaluateEgo(est, gt);
  EXPECT_NEAR(*m.t_rel_pct, expected(kDevkitLengths), 1e-9);
  EXPECT_NEAR(*m.t_rel_short_pct, expected(kShortLengths), 1e-9);
  EXPECT_NEAR(*m.t_rel_pct, 1.0, 0.01);  // about the 1 % drift
  EXPECT_NEAR(*m.r_rel_deg_per_100m, 0.0, 1e-12);
  // Segments of length 100: first frames 0, 10, ..., 890 (the last needs frame first + 101 <= 999).
  EXPECT_EQ(m.devkit->lengths.front(), 100);
  EXPECT_EQ(m.devkit->lengths.back(), 800);
}

TEST(EvalEgo, HeadingDriftGivesTheDevkitsRotationError) {
  // Positions exact, heading off by 0.001 rad more every frame: a segment of k frames has a
  // rotation error of k * 0.001 rad; with 1 m frames k = L + 1.
  const int n = 900;
  const double eps = 0.001;
  const Trajectory gt = straightLine(n, 1.0);
  Trajectory est = gt;
  for (int i = 0; i < n; ++i) est.poses[i].linear() = Eigen::AngleAxisd(eps * i, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  double sum = 0;
  int count = 0;
  for (int first = 0; first < n; first += 10)
    for (double L : kShortLengths)
      if (first + L + 1 <= n - 1) {
        sum += eps * (L + 1) / L;
        ++count;
      }
  const auto s = segmentErrors(est, gt, kShortLengths);
  ASSERT_TRUE(s);
  EXPECT_EQ(s->segments, count);
  EXPECT_NEAR(s->r_rel_deg_per_100m, 100.0 * 180.0 / M_PI * sum / count, 1e-6);
}

TEST(EvalEgo, ShortSequencesHaveNoDevkitSegmentsButShortOnes) {
  const Trajectory gt = straightLine(60, 1.0);  // 59 m
  const EgoMetrics m = evaluateEgo(gt, gt);
  EXPECT_FALSE(m.t_rel_pct);
  EXPECT_FALSE(m.r_rel_deg_per_100m);
  EXPECT_TRUE(m.t_rel_short_pct);
}

TEST(EvalEgo, TrajectoriesOverDifferentFramesAreRejected) {
  const Trajectory a = straightLine(10, 1.0), b = straightLine(11, 1.0);
  EXPECT_THROW(evaluateEgo(a, b), std::invalid_argument);
  const auto [ca, cb] = commonFrames(a, b);
  EXPECT_EQ(ca.size(), 10u);
  EXPECT_EQ(cb.frames, ca.frames);
}

TEST(EvalEgo, TrajectoryFilesRoundTripInEveryFormat) {
  const auto dir = tempDir("files");
  const Trajectory t = curvedDrive(30);
  // Velodyne -> camera 0 as in KITTI: camera x = -lidar y, y = -lidar z, z = lidar x.
  Pose Tr = Pose::Identity();
  Tr.linear() << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  Tr.translation() << -0.004, -0.076, -0.27;
  for (TrajectoryFormat f : {TrajectoryFormat::Kitti, TrajectoryFormat::KittiCam, TrajectoryFormat::Tum}) {
    const std::string path = (dir / ("t_" + formatName(f) + ".txt")).string();
    writeTrajectory(path, t, f, Tr);
    const Trajectory back = readTrajectory(path, f, Tr);
    ASSERT_EQ(back.size(), t.size()) << formatName(f);
    for (size_t i = 0; i < t.size(); ++i) {
      EXPECT_TRUE(back.poses[i].isApprox(t.poses[i], 1e-8)) << formatName(f) << " frame " << i;
      EXPECT_NEAR(back.stamps[i], t.stamps[i], 1e-6);
    }
  }
  // kitti_cam is T_cam = Tr * T * inv(Tr): the first pose stays the identity, a forward lidar
  // motion (x) becomes a forward camera motion (z).
  const std::string path = (dir / "cam.txt").string();
  writeTrajectory(path, straightLine(2, 1.0), TrajectoryFormat::KittiCam, Tr);
  const Trajectory cam = readTrajectory(path, TrajectoryFormat::Kitti);
  EXPECT_TRUE(cam.poses[0].isApprox(Pose::Identity(), 1e-12));
  EXPECT_NEAR(cam.poses[1].translation().x(), 0.0, 1e-9);
  EXPECT_NEAR(cam.poses[1].translation().z(), 1.0, 1e-9);
  EXPECT_THROW(writeTrajectory(path, t, TrajectoryFormat::KittiCam), InputError);  // no calibration
  std::filesystem::remove_all(dir);
}

TEST(EvalEgo, BadTrajectoryFilesNameFileAndLine) {
  const auto dir = tempDir("bad");
  const std::string path = (dir / "bad_tum.txt").string();
  {
    std::ofstream out(path);
    out << "# comment\n0.0 0 0 0 0 0 0 1\n0.1 1 2 3 0 0\n";
  }
  try {
    readTrajectory(path, TrajectoryFormat::Tum);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path + ":3"), std::string::npos) << e.what();
  }
  EXPECT_THROW(readTrajectory((dir / "missing.txt").string(), TrajectoryFormat::Kitti), InputError);
  EXPECT_THROW(parseTrajectoryFormat("euroc"), std::invalid_argument);
  std::filesystem::remove_all(dir);
}

TEST(EvalEgo, ARunStartingLaterInTheSequenceIsComparedInItsOwnWorld) {
  // The run starts at frame 10: its world is the lidar frame of scan 10.
  const Trajectory gt = curvedDrive(40);
  Trajectory est;
  const Pose world_change = gt.poses[10].inverse();
  for (size_t i = 10; i < gt.size(); ++i) est.add(gt.frames[i], gt.stamps[i], world_change * gt.poses[i]);
  RunData run;
  run.sources["slot"] = est;
  run.truth = gt;
  const Metrics m = evaluate(run, EvalOptions());
  const EgoMetrics& e = *m.ego.at("slot");
  EXPECT_EQ(e.frames, 30);
  EXPECT_NEAR(*e.ate_unaligned_rmse_m, 0.0, 1e-9);
  EXPECT_NEAR(*e.ate_rmse_m, 0.0, 1e-9);
  EXPECT_NEAR(*e.rpe1_t_m, 0.0, 1e-9);
  EXPECT_EQ(m.primary_source, "slot");
  EXPECT_FALSE(m.tracking);  // no labels
}

// Speed jumps: braking at 1 g is a car's, not a jump; a velocity re-anchored from 0.2 to 2.4 m per
// scan (the odometry's recovery from a wrong speed) is one; without stamps nothing is said.
TEST(EgoImplausible, CountsSpeedJumpsAboveTwoG) {
  auto drive = [](const std::vector<double>& steps, bool stamped) {
    Trajectory t;
    Pose T = Pose::Identity();
    t.add(0, stamped ? 0.0 : -1.0, T);
    for (size_t i = 0; i < steps.size(); ++i) {
      T.translation().x() += steps[i];
      t.add(static_cast<int>(i + 1), stamped ? 0.1 * static_cast<double>(i + 1) : -1.0, T);
    }
    if (!stamped) t.stamps.clear();
    return t;
  };
  std::vector<double> braking;  // 25 m/s, 1 g: 0.098 m/s less per 0.1 s scan
  for (double v = 25.0; v > 0; v -= 0.981) braking.push_back(0.1 * v);
  EXPECT_EQ(implausibleSpeedJumps(drive(braking, true)), 0.0);
  std::vector<double> reanchored(10, 0.2);
  for (int i = 0; i < 10; ++i) reanchored.push_back(2.4);
  EXPECT_EQ(implausibleSpeedJumps(drive(reanchored, true)), 1.0);
  EXPECT_FALSE(implausibleSpeedJumps(drive(reanchored, false)).has_value());
}
