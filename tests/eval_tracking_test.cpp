// Tracking metrics of the evaluator (box overlap, CLEAR MOT, HOTA, velocities) against
// hand-computed answers.
#include <gtest/gtest.h>

#include <cmath>

#include "assignment.hpp"
#include "box_overlap.hpp"
#include "clear_mot.hpp"
#include "evaluation.hpp"
#include "hota.hpp"
#include "tracking_frames.hpp"
#include "velocity.hpp"

using namespace dlslot;
using namespace dlslot::eval;

namespace {

Box box(double x, double y, int id, const std::string& type = "Car", double yaw = 0.0,
        Eigen::Vector3d size = Eigen::Vector3d(4, 2, 1.5)) {
  Box b;
  b.center = Eigen::Vector3d(x, y, 0.75);
  b.size = size;
  b.yaw = yaw;
  b.type = type;
  b.id = id;
  return b;
}

Object obj(double x, double y, int id, const std::string& type = "Car") { return {box(x, y, id, type), std::nullopt, false}; }

const MatchCriterion kDistance;                                   // centre distance <= 2 m
const MatchCriterion kIou{MatchCriterion::Kind::Iou3d};          // 3D IoU >= 0.25

}  // namespace

// ---------------- box overlap ----------------

TEST(EvalBoxOverlap, IouOfKnownBoxes) {
  const Eigen::Vector3d cube(2, 2, 2);
  EXPECT_NEAR(iou3d(box(0, 0, 1, "Car", 0, cube), box(0, 0, 2, "Car", 0, cube)), 1.0, 1e-12);
  // Shifted by half a side: intersection 1 x 2 x 2 = 4, union 8 + 8 - 4 = 12.
  EXPECT_NEAR(iou3d(box(0, 0, 1, "Car", 0, cube), box(1, 0, 2, "Car", 0, cube)), 1.0 / 3.0, 1e-12);
  // Shifted diagonally by (1, 1): 1 x 1 x 2 = 2 over 14.
  EXPECT_NEAR(iou3d(box(0, 0, 1, "Car", 0, cube), box(1, 1, 2, "Car", 0, cube)), 2.0 / 14.0, 1e-12);
  // A unit square and the same square turned 45 degrees: a regular octagon of area 2 (sqrt 2 - 1);
  // with equal heights the IoU is 1 / sqrt 2.
  const Eigen::Vector3d unit(1, 1, 1);
  EXPECT_NEAR(bevIntersectionArea(box(0, 0, 1, "Car", 0, unit), box(0, 0, 2, "Car", M_PI / 4, unit)),
              2.0 * (std::sqrt(2.0) - 1.0), 1e-12);
  EXPECT_NEAR(iou3d(box(0, 0, 1, "Car", 0, unit), box(0, 0, 2, "Car", M_PI / 4, unit)), 1.0 / std::sqrt(2.0), 1e-12);
  // Heights overlapping by half: intersection 4 x 2 x 0.75 = 6, union 12 + 12 - 6 = 18.
  Box high = box(0, 0, 2);
  high.center.z() += 0.75;
  EXPECT_NEAR(iou3d(box(0, 0, 1), high), 6.0 / 18.0, 1e-12);
  // A car turned by 90 degrees over another: the 2 x 2 middle square, 4 x 1.5 = 6 over 18.
  EXPECT_NEAR(iou3d(box(0, 0, 1), box(0, 0, 2, "Car", M_PI / 2)), 6.0 / 18.0, 1e-12);
  EXPECT_EQ(iou3d(box(0, 0, 1), box(10, 0, 2)), 0.0);
  EXPECT_EQ(iou3d(box(0, 0, 1), box(0, 0, 2, "Car", 0, Eigen::Vector3d::Zero())), 0.0);
}

TEST(EvalBoxOverlap, FootprintAndDistance) {
  EXPECT_NEAR(bevDistance(box(0, 0, 1), box(3, 4, 2)), 5.0, 1e-12);
  EXPECT_TRUE(footprintContains(box(0, 0, 1, "Car", M_PI / 2), Eigen::Vector3d(0, 1.9, 50)));
  EXPECT_FALSE(footprintContains(box(0, 0, 1, "Car", M_PI / 2), Eigen::Vector3d(1.9, 0, 0)));
}

// ---------------- assignment ----------------

TEST(EvalAssignment, NeverReturnsAForbiddenPair) {
  // Forbidden pairs are never returned, even when a row has nothing else.
  const auto col = assignAllowedPairs(2, 2, [](int i, int j) -> std::optional<double> {
    if (i == 1) return std::nullopt;
    return j == 0 ? 1.0 : 2.0;
  });
  EXPECT_EQ(col, (std::vector<int>{0, -1}));
  // Most pairs first: matching (0,1) and (1,0) beats the single cheapest pair (0,0).
  const auto most = assignAllowedPairs(2, 2, [](int i, int j) -> std::optional<double> {
    if (i == 1 && j == 1) return std::nullopt;
    return i == 0 && j == 0 ? 0.0 : 1.0;
  });
  EXPECT_EQ(most, (std::vector<int>{1, 0}));
}

// ---------------- CLEAR MOT and HOTA ----------------

TEST(EvalTracking, PerfectTrackerScoresPerfectly) {
  std::vector<TrackingFrame> frames;
  for (int t = 0; t < 10; ++t) {
    TrackingFrame f;
    f.frame = t;
    for (int k = 0; k < 3; ++k) {
      f.truth.push_back(obj(10.0 * k + t, 5.0 * k, k));
      f.tracks.push_back(obj(10.0 * k + t, 5.0 * k, 100 + k));
    }
    frames.push_back(f);
  }
  for (const MatchCriterion& c : {kDistance, kIou}) {
    const ClearMot m = evaluateClearMot(frames, c);
    EXPECT_EQ(m.num_truth, 30);
    EXPECT_EQ(m.tp, 30);
    EXPECT_EQ(m.fp, 0);
    EXPECT_EQ(m.fn, 0);
    EXPECT_EQ(m.idsw, 0);
    EXPECT_DOUBLE_EQ(*m.mota, 1.0);
    EXPECT_NEAR(*m.motp_m, 0.0, 1e-12);
    const auto h = evaluateHota(frames, c);
    ASSERT_TRUE(h);
    EXPECT_NEAR(h->hota, 1.0, 1e-12) << c.describe();
    EXPECT_NEAR(h->deta, 1.0, 1e-12);
    EXPECT_NEAR(h->assa, 1.0, 1e-12);
  }
}

TEST(EvalTracking, IdSwapCountsTwoSwitchesAndThirdsTheAssociation) {
  // Labels A (id 1) at x = 0 and B (id 2) at x = 50 for 4 frames; tracks 10 and 20 follow A and B
  // for two frames, then swap. CLEAR: 2 switches (frame 2, one per label), MOTA = 1 - 2/8.
  // HOTA: every detection is exact (DetA = 1); each (label, track) pair is matched in 2 frames
  // while each id lives 4 frames, so every TP has association IoU 2 / (4 + 4 - 2) = 1/3:
  // AssA = 1/3 and HOTA = sqrt(1/3) at every alpha.
  std::vector<TrackingFrame> frames;
  for (int t = 0; t < 4; ++t) {
    TrackingFrame f;
    f.frame = t;
    f.truth = {obj(0, t, 1), obj(50, t, 2)};
    const bool swapped = t >= 2;
    f.tracks = {obj(0, t, swapped ? 20 : 10), obj(50, t, swapped ? 10 : 20)};
    frames.push_back(f);
  }
  const ClearMot m = evaluateClearMot(frames, kDistance);
  EXPECT_EQ(m.idsw, 2);
  EXPECT_EQ(m.fp, 0);
  EXPECT_EQ(m.fn, 0);
  EXPECT_DOUBLE_EQ(*m.mota, 0.75);
  const auto h = evaluateHota(frames, kDistance);
  EXPECT_NEAR(h->deta, 1.0, 1e-12);
  EXPECT_NEAR(h->assa, 1.0 / 3.0, 1e-12);
  EXPECT_NEAR(h->hota, std::sqrt(1.0 / 3.0), 1e-12);
}

TEST(EvalTracking, HeadingErrorOfMovingCars) {
  // Frame 0: a car moving at 10 m/s, tracked 2 deg off; frame 1: the same car at yaw 179 deg,
  // tracked at -179 deg (2 deg across the wrap, not 358). Not counted: a dynamic car crawling at
  // 0.5 m/s tracked 30 deg off, a static car 50 deg off, a moving pedestrian 40 deg off.
  // Heading RMSE = sqrt((2^2 + 2^2) / 2) = 2 deg over 2 pairs.
  const double deg = M_PI / 180;
  const auto label = [](Box b, double speed, bool dynamic) { return Object{b, Eigen::Vector2d(speed, 0), dynamic}; };
  std::vector<TrackingFrame> frames(2);
  for (int t = 0; t < 2; ++t) {
    const double yaw = t == 0 ? 10 * deg : 179 * deg, tracked = t == 0 ? 12 * deg : -179 * deg;
    frames[t].frame = t;
    frames[t].truth = {label(box(0, t, 1, "Car", yaw), 10, true), label(box(20, 0, 2, "Car", 0), 0.5, true),
                       label(box(40, 0, 3, "Car", 0), 0, false), label(box(60, 0, 4, "Pedestrian", 0), 1.5, true)};
    frames[t].tracks = {label(box(0, t, 10, "Car", tracked), 10, false), label(box(20, 0, 20, "Car", 30 * deg), 0.5, false),
                        label(box(40, 0, 30, "Car", 50 * deg), 0, false),
                        label(box(60, 0, 40, "Pedestrian", 40 * deg), 1.5, false)};
  }
  const ClearMot m = evaluateClearMot(frames, kDistance);
  EXPECT_EQ(m.tp, 8);
  EXPECT_EQ(m.heading_pairs, 2);
  ASSERT_TRUE(m.heading_rmse_deg);
  EXPECT_NEAR(*m.heading_rmse_deg, 2.0, 1e-9);
  EXPECT_EQ(m.heading_reversed, 0);
  EXPECT_NEAR(*m.heading_rmse_unreversed_deg, 2.0, 1e-9);
  // The car tracked the wrong way round in frame 0: 180 deg; sqrt((180^2 + 2^2) / 2) over both,
  // one reversed, 2 deg for the other.
  frames[0].tracks[0].box.yaw = 10 * deg + M_PI;
  const ClearMot r = evaluateClearMot(frames, kDistance);
  EXPECT_NEAR(*r.heading_rmse_deg, std::sqrt((180.0 * 180.0 + 4.0) / 2), 1e-9);
  EXPECT_EQ(r.heading_reversed, 1);
  EXPECT_NEAR(*r.heading_rmse_unreversed_deg, 2.0, 1e-9);
}

TEST(EvalTracking, MissesAndFalsePositives) {
  // One label over 5 frames, tracked (id 10) in frames 0, 1, 4 only: FN = 2; a spurious track
  // (id 99) far away in frame 3: FP = 1. MOTA = 1 - 3/5 = 0.4.
  // HOTA: TP 3, FN 2, FP 1 -> DetA = 3/6; the pair (1, 10) is matched 3 times, label 1 lives 5
  // frames and track 10 three: association IoU 3 / (5 + 3 - 3) = 0.6 = AssA; HOTA = sqrt(0.3).
  std::vector<TrackingFrame> frames;
  for (int t = 0; t < 5; ++t) {
    TrackingFrame f;
    f.frame = t;
    f.truth = {obj(t, 0, 1)};
    if (t == 0 || t == 1 || t == 4) f.tracks.push_back(obj(t, 0, 10));
    if (t == 3) f.tracks.push_back(obj(30, 30, 99));
    frames.push_back(f);
  }
  const ClearMot m = evaluateClearMot(frames, kDistance);
  EXPECT_EQ(m.fn, 2);
  EXPECT_EQ(m.fp, 1);
  EXPECT_EQ(m.idsw, 0);  // the same track resumes: a fragmentation, not a switch
  EXPECT_NEAR(*m.mota, 0.4, 1e-12);
  const auto h = evaluateHota(frames, kDistance);
  EXPECT_NEAR(h->deta, 0.5, 1e-12);
  EXPECT_NEAR(h->assa, 0.6, 1e-12);
  EXPECT_NEAR(h->hota, std::sqrt(0.3), 1e-12);
}

TEST(EvalTracking, LocalisationErrorLowersHotaAndSetsMotp) {
  // Every track 0.5 m beside its label: distance similarity 1 - 0.5/2 = 0.75, a true positive
  // for alpha = 0.05 .. 0.75 (15 of 19 thresholds), with DetA = AssA = 1 there.
  std::vector<TrackingFrame> frames;
  for (int t = 0; t < 6; ++t) {
    TrackingFrame f;
    f.frame = t;
    f.truth = {obj(t, 0, 1)};
    f.tracks = {obj(t, 0.5, 7)};
    frames.push_back(f);
  }
  const ClearMot m = evaluateClearMot(frames, kDistance);
  EXPECT_NEAR(*m.motp_m, 0.5, 1e-12);
  EXPECT_DOUBLE_EQ(*m.mota, 1.0);
  const auto h = evaluateHota(frames, kDistance);
  EXPECT_NEAR(h->hota, 15.0 / 19.0, 1e-12);
  EXPECT_NEAR(h->loca, 0.75 * 15.0 / 19.0, 1e-12);
  // 2.5 m away is outside the 2 m gate: a miss and a false positive per frame.
  for (auto& f : frames) f.tracks[0].box.center.y() = 2.5;
  const ClearMot far = evaluateClearMot(frames, kDistance);
  EXPECT_EQ(far.tp, 0);
  EXPECT_EQ(far.fn, 6);
  EXPECT_EQ(far.fp, 6);
  EXPECT_NEAR(*far.mota, -1.0, 1e-12);
  EXPECT_NEAR(evaluateHota(frames, kDistance)->hota, 0.0, 1e-12);
}

TEST(EvalTracking, KeepsTheLastCorrespondenceWhileItIsValid) {
  // Track 10 follows the label 1 m off; from frame 1 track 20 sits exactly on it. CLEAR MOT keeps
  // the existing correspondence (no switch); track 20 is a false positive.
  std::vector<TrackingFrame> frames(3);
  for (int t = 0; t < 3; ++t) {
    frames[t].frame = t;
    frames[t].truth = {obj(0, 0, 1)};
    frames[t].tracks = {obj(1, 0, 10)};
    if (t > 0) frames[t].tracks.push_back(obj(0, 0, 20));
  }
  const ClearMot m = evaluateClearMot(frames, kDistance);
  EXPECT_EQ(m.idsw, 0);
  EXPECT_EQ(m.fp, 2);
  EXPECT_NEAR(*m.motp_m, 1.0, 1e-12);
}

TEST(EvalTracking, ClassesMatchAsInTheKittiDevkit) {
  TrackingFrame f;
  f.truth = {obj(0, 0, 1, "Van"), obj(20, 0, 2, "Pedestrian")};
  f.tracks = {obj(0, 0, 10, "Car"), obj(20, 0, 11, "Car")};
  const ClearMot m = evaluateClearMot({f}, kDistance);
  EXPECT_EQ(m.tp, 1);  // Car ~ Van
  EXPECT_EQ(m.fp, 1);  // a Car is no Pedestrian
  EXPECT_EQ(m.fn, 1);
  // Evaluating only cars: the Van (a neighbouring class) becomes an ignore region, so the Car
  // track on it is neither FP nor TP; the pedestrian label is not evaluated at all.
  std::vector<TrackingFrame> only_cars = {f};
  restrictClasses(only_cars, {"Car"});
  dropIgnoredTracks(only_cars, kDistance);
  const ClearMot c = evaluateClearMot(only_cars, kDistance);
  EXPECT_EQ(c.num_truth, 0);
  EXPECT_EQ(c.fp, 1);  // the Car track on the pedestrian
  EXPECT_FALSE(c.mota);
}

TEST(EvalTracking, TracksInDontCareRegionsAreNeitherFalseNorTruePositives) {
  TrackingFrame f;
  f.truth = {obj(0, 0, 1)};
  f.ignore = {box(30, 0, -1, "DontCare", 0, Eigen::Vector3d(10, 10, 3))};
  f.tracks = {obj(0, 0, 10), obj(33, 2, 11), obj(60, 0, 12)};
  std::vector<TrackingFrame> frames = {f};
  dropIgnoredTracks(frames, kDistance);
  ASSERT_EQ(frames[0].tracks.size(), 2u);
  const ClearMot m = evaluateClearMot(frames, kDistance);
  EXPECT_EQ(m.tp, 1);
  EXPECT_EQ(m.fp, 1);  // only the track at x = 60
  // A track matched to a label stays even inside a DontCare region.
  TrackingFrame g;
  g.truth = {obj(30, 0, 1)};
  g.ignore = f.ignore;
  g.tracks = {obj(30, 0.5, 10)};
  std::vector<TrackingFrame> inside = {g};
  dropIgnoredTracks(inside, kDistance);
  EXPECT_EQ(evaluateClearMot(inside, kDistance).tp, 1);
}

TEST(EvalTracking, NoLabelsAndNoTracksAreNotMeasurable) {
  std::vector<TrackingFrame> frames(3);
  EXPECT_FALSE(evaluateClearMot(frames, kDistance).mota);
  EXPECT_FALSE(evaluateHota(frames, kDistance));
}

// ---------------- velocities ----------------

TEST(EvalVelocity, WorldVelocitiesAreExpressedInEachScansLidarAxes) {
  // An object drives along world +x at 10 m/s; the ego moves along world +y at 5 m/s, heading
  // +y (yaw 90 deg). In the lidar axes the object's velocity over ground is (0, -10).
  std::vector<TrackingFrame> frames;
  for (int t = 0; t < 5; ++t) {
    TrackingFrame f;
    f.frame = t;
    f.stamp = 0.1 * t;
    Pose ego = Pose::Identity();
    ego.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    ego.translation() << 0, 0.5 * t, 0;
    f.truth_pose = ego;
    Box world = box(1.0 * t, 20, 1);
    f.truth = {{world.transformed(ego.inverse()), std::nullopt, false}};
    frames.push_back(f);
  }
  finiteDifferenceVelocities(frames, Side::Truth, VelocityFrame::World, true);
  markDynamicLabels(frames, VelocityFrame::World, 0.5);
  for (const auto& f : frames) {
    ASSERT_TRUE(f.truth[0].velocity);
    EXPECT_NEAR(f.truth[0].velocity->x(), 0.0, 1e-9);
    EXPECT_NEAR(f.truth[0].velocity->y(), -10.0, 1e-9);
    EXPECT_TRUE(f.truth[0].dynamic);
  }
  // In the sensor frame a parked object seen from an ego driving 10 m/s forward moves backwards.
  std::vector<TrackingFrame> sensor(3);
  for (int t = 0; t < 3; ++t) {
    sensor[t].stamp = 0.1 * t;
    sensor[t].truth = {obj(20.0 - 1.0 * t, 0, 1)};
  }
  finiteDifferenceVelocities(sensor, Side::Truth, VelocityFrame::Sensor, true);
  EXPECT_NEAR(sensor[1].truth[0].velocity->x(), -10.0, 1e-9);
  EXPECT_THROW(finiteDifferenceVelocities(sensor, Side::Truth, VelocityFrame::World, true), std::invalid_argument);
}

TEST(EvalVelocity, LabelsDifferencedOverASpanAverageTheLabellersJitter) {
  // A car accelerating at 1 m/s^2 from 2 m/s, labelled every 0.1 s, once without and once with a
  // labeller's jitter (up to 0.1 m); the label of frame 20 is missing.
  auto labels = [](double jitter_m) {
    std::vector<TrackingFrame> frames(31);
    for (int t = 0; t < 31; ++t) {
      const double s = 0.1 * t;
      frames[t].stamp = s;
      frames[t].truth_pose = Pose::Identity();
      const double j = jitter_m * (((t * 7) % 5) - 2) / 2.0;
      if (t != 20) frames[t].truth = {obj(20 + 2 * s + 0.5 * s * s + j, 0, 1)};
    }
    return frames;
  };
  auto truth = [](int t) { return 2.0 + 0.1 * t; };
  // Exact labels: a symmetric central difference is exact for constant acceleration, over any span.
  std::vector<TrackingFrame> exact = labels(0.0);
  finiteDifferenceVelocities(exact, Side::Truth, VelocityFrame::World, true, 0.5);
  for (int t = 1; t < 30; ++t) {
    if (t == 20) continue;
    ASSERT_TRUE(exact[t].truth[0].velocity) << t;
    EXPECT_NEAR(exact[t].truth[0].velocity->x(), truth(t), 1e-9) << t;
  }
  // Jittered labels: over +-0.5 s the labeller's noise is a fraction of the neighbours'.
  double near_sq = 0, span_sq = 0;
  std::vector<TrackingFrame> near = labels(0.1), span = labels(0.1);
  finiteDifferenceVelocities(near, Side::Truth, VelocityFrame::World, true);
  finiteDifferenceVelocities(span, Side::Truth, VelocityFrame::World, true, 0.5);
  for (int t = 5; t <= 25; ++t) {
    if (t == 20) continue;
    near_sq += std::pow(near[t].truth[0].velocity->x() - truth(t), 2);
    span_sq += std::pow(span[t].truth[0].velocity->x() - truth(t), 2);
  }
  EXPECT_GT(near_sq, 0.1);
  EXPECT_LT(span_sq, 0.1 * near_sq);
  // The span is chosen from the labels: a human's (ahead of the sensor only) or the simulator's.
  EXPECT_EQ(labelVelocityHalfSpan(exact), 0.5);
  exact[3].truth.push_back(obj(-15, 2, 7));
  EXPECT_EQ(labelVelocityHalfSpan(exact), 0.0);
}

TEST(EvalVelocity, RmseOverMatchedDynamicLabels) {
  std::vector<TrackingFrame> frames(2);
  for (int t = 0; t < 2; ++t) {
    frames[t].truth = {obj(0, 0, 1), obj(20, 0, 2)};
    frames[t].truth[0].velocity = Eigen::Vector2d(10, 0);
    frames[t].truth[0].dynamic = true;
    frames[t].truth[1].velocity = Eigen::Vector2d(0, 0);  // parked: not counted
    frames[t].tracks = {obj(0, 0, 5), obj(20, 0, 6)};
    frames[t].tracks[0].velocity = Eigen::Vector2d(t == 0 ? 11 : 10, t == 0 ? 0 : 3);
    frames[t].tracks[1].velocity = Eigen::Vector2d(5, 5);
  }
  const ClearMot m = evaluateClearMot(frames, kDistance);
  EXPECT_EQ(m.velocity_pairs, 2);
  EXPECT_NEAR(*m.velocity_rmse_mps, std::sqrt((1.0 + 9.0) / 2.0), 1e-12);
}

TEST(EvalVelocity, EvaluateComparesTheSystemsVelocityWithGroundTruthMotion) {
  // Full evaluate(): labels move 10 m/s along x in a world the ego does not move in; the
  // tracks carry the system's velocity estimate, 1 m/s too fast.
  RunData run;
  run.has_labels = run.has_tracks = run.track_velocities_given = true;
  for (int t = 0; t < 5; ++t) {
    TrackingFrame f;
    f.frame = t;
    f.stamp = 0.1 * t;
    f.truth_pose = f.ego_pose = Pose::Identity();
    f.truth = {obj(1.0 * t, 0, 1)};
    f.tracks = {obj(1.0 * t, 0, 3)};
    f.tracks[0].velocity = Eigen::Vector2d(11, 0);
    run.tracking.push_back(f);
  }
  const Metrics m = evaluate(run, EvalOptions());
  ASSERT_TRUE(m.tracking);
  EXPECT_NEAR(*m.tracking->clear.velocity_rmse_mps, 1.0, 1e-9);
  EXPECT_NEAR(m.tracking->hota->hota, 1.0, 1e-12);
  EXPECT_NE(m.velocity_frame.find("world"), std::string::npos);
}

TEST(EvalTracking, EveryClassIsScoredAllAroundOnItsOwn) {
  // Two cars and a pedestrian labelled in 4 frames; the cars are tracked throughout, the
  // pedestrian only in the last two frames, and a false pedestrian track appears once. Per class:
  // car MOTA 1; pedestrian 2 misses + 1 false positive of 4 labels -> MOTA 0.25; no cyclist row.
  RunData run;
  run.has_labels = run.has_tracks = true;
  for (int t = 0; t < 4; ++t) {
    TrackingFrame f;
    f.frame = t;
    f.stamp = 0.1 * t;
    f.truth = {obj(10, 0, 1), obj(20, 5, 2), obj(5, -3, 3, "Pedestrian")};
    f.tracks = {obj(10.2, 0, 11), obj(20, 5.1, 12)};
    if (t >= 2) f.tracks.push_back(obj(5.1, -3, 13, "Pedestrian"));
    if (t == 0) f.tracks.push_back(obj(-8, 9, 14, "Pedestrian"));
    run.tracking.push_back(f);
  }
  const Metrics m = evaluate(run, EvalOptions());
  ASSERT_EQ(m.tracking_by_class.size(), 2u);
  const ClearMot& car = m.tracking_by_class.at("car");
  EXPECT_EQ(car.num_truth, 8);
  EXPECT_EQ(car.tp, 8);
  EXPECT_NEAR(*car.mota, 1.0, 1e-12);
  const ClearMot& ped = m.tracking_by_class.at("pedestrian");
  EXPECT_EQ(ped.num_truth, 4);
  EXPECT_EQ(ped.fn, 2);
  EXPECT_EQ(ped.fp, 1);
  EXPECT_NEAR(*ped.mota, 0.25, 1e-12);
  EXPECT_EQ(m.tracking_by_class.count("cyclist"), 0u);
}

TEST(EvalTracking, VelocityErrorsAreBrokenDownByAgeClassMotionRangeAndStretch) {
  // One car tracked from frame 0 10 m away, a van from frame 10 22 m away, a parked car; 20
  // frames. The car's track is 1 m/s off along x, the van's 2 m/s, the parked car's 0.5 m/s.
  std::vector<TrackingFrame> frames;
  for (int t = 0; t < 20; ++t) {
    TrackingFrame f;
    f.frame = t;
    auto add = [&](double x, double y, int id, const std::string& type, double v_truth, double v_track, bool dynamic) {
      Object g = obj(x, y, id, type), h = obj(x, y, 100 + id, type);
      g.velocity = Eigen::Vector2d(v_truth, 0);
      g.dynamic = dynamic;
      h.velocity = Eigen::Vector2d(v_track, 0);
      f.truth.push_back(g);
      f.tracks.push_back(h);
    };
    add(10, 0, 1, "Car", 10, 11, true);
    if (t >= 10) add(20, 10, 2, "Van", 5, 7, true);
    add(30, -10, 3, "Car", 0, 0.5, false);
    frames.push_back(f);
  }
  const ClearMot m = evaluateClearMot(frames, kDistance);
  EXPECT_EQ(m.velocities.size(), 50u);
  EXPECT_EQ(m.velocity_pairs, 30);  // dynamic labels only
  const auto groups = breakdownVelocityErrors(m.velocities, 20);
  auto find = [&](const std::string& by, const std::string& bin) -> const VelocityGroup& {
    for (const VelocityGroup& g : groups)
      if (g.dimension == by && g.bin == bin) return g;
    ADD_FAILURE() << by << " " << bin << " missing";
    static VelocityGroup none;
    return none;
  };
  // Ages 0-4: the car's frames 0-4 and the van's 10-14 (errors 1 and 2).
  EXPECT_EQ(find("age", "0-4").pairs, 10);
  EXPECT_NEAR(*find("age", "0-4").rmse_mps, std::sqrt((5 * 1.0 + 5 * 4.0) / 10), 1e-12);
  EXPECT_EQ(find("age", "10-19").pairs, 10);  // the car's frames 10-19
  EXPECT_NEAR(*find("age", "10-19").rmse_mps, 1.0, 1e-12);
  EXPECT_NEAR(*find("class", "van").rmse_mps, 2.0, 1e-12);
  EXPECT_EQ(find("class", "car").pairs, 20);  // the parked car is not dynamic
  EXPECT_NEAR(*find("motion", "static").rmse_mps, 0.5, 1e-12);
  EXPECT_EQ(find("motion", "dynamic").pairs, 30);
  EXPECT_EQ(find("range", "0-20").pairs, 20);  // the car; the parked car (32 m) is not dynamic
  EXPECT_NEAR(*find("range", "0-20").rmse_mps, 1.0, 1e-12);
  EXPECT_EQ(find("range", "20-40").pairs, 10);  // the van
  EXPECT_NEAR(*find("range", "20-40").rmse_mps, 2.0, 1e-12);
  for (const VelocityGroup& g : groups) EXPECT_FALSE(g.dimension == "range" && (g.bin == "40-60" || g.bin == "60+"));
  EXPECT_EQ(find("frames", "000-001").pairs, 2);
  EXPECT_NEAR(*find("frames", "018-019").rmse_mps, std::sqrt((2 * 1.0 + 2 * 4.0) / 4), 1e-12);
}

TEST(EvalVelocity, TheTracksCovarianceIsCheckedAgainstItsErrors) {
  // A car tracked for 10 frames, 1 m/s too fast along x, its track's velocity covariance
  // diag(0.25, 1) from frame 2 on (sigma 0.5 m/s along x: NEES (1 / 0.5)^2 = 4, inside the 95 %
  // ellipse), diag(0.04, 1) from frame 6 on (sigma 0.2: NEES 25, outside it); frames 0-1 without
  // one; a parked car's pair never counts.
  std::vector<TrackingFrame> frames;
  for (int t = 0; t < 10; ++t) {
    TrackingFrame f;
    f.frame = t;
    Object g = obj(10, 0, 1), h = obj(10, 0, 101), parked = obj(30, 5, 2), parked_track = obj(30, 5, 102);
    g.velocity = Eigen::Vector2d(10, 0);
    g.dynamic = true;
    h.velocity = Eigen::Vector2d(11, 0);
    if (t >= 2) h.velocity_covariance = Eigen::Vector2d(t >= 6 ? 0.04 : 0.25, 1.0).asDiagonal();
    parked.velocity = parked_track.velocity = Eigen::Vector2d::Zero();
    parked_track.velocity_covariance = Eigen::Matrix2d::Identity();
    f.truth = {g, parked};
    f.tracks = {h, parked_track};
    frames.push_back(f);
  }
  const ClearMot m = evaluateClearMot(frames, kDistance);
  ASSERT_EQ(m.velocities.size(), 20u);
  EXPECT_FALSE(m.velocities[0].nees());
  const VelocityCalibration all = velocityCalibration(m.velocities, 0, 100);
  EXPECT_EQ(all.pairs, 8);
  EXPECT_NEAR(*all.nees_mean, (4 * 4.0 + 4 * 25.0) / 8, 1e-9);
  EXPECT_NEAR(*all.within_95, 0.5, 1e-12);
  const VelocityCalibration young = velocityCalibration(m.velocities, 0, 4);  // frames 2-4
  EXPECT_EQ(young.pairs, 3);
  EXPECT_NEAR(*young.within_95, 1.0, 1e-12);
  EXPECT_FALSE(velocityCalibration(m.velocities, 20, 100).nees_mean);
}

TEST(EvalVelocity, ErrorsByRangeBesideWhatTheTracksCovariancesPredict) {
  // Dynamic pairs: at 5 m three mature ones 0.3 m/s off with covariance diag(0.04, 0.05) (own RMS
  // 0.3); at 25 m two 1 m/s off with none, one 2 m/s off with diag(1, 3); a young pair at 5 m,
  // a parked car's pair at 25 m and a lone pair at 45 m (under min_pairs) count nowhere.
  std::vector<VelocityPair> pairs;
  auto add = [&](double range, double error, int age, bool dynamic, std::optional<Eigen::Matrix2d> cov) {
    VelocityPair p;
    p.range_m = range;
    p.track_age = age;
    p.dynamic = dynamic;
    p.truth = Eigen::Vector2d(10, 0);
    p.track = Eigen::Vector2d(10, error);
    p.track_covariance = cov;
    pairs.push_back(p);
  };
  for (int k = 0; k < 3; ++k) add(5, 0.3, 20, true, Eigen::Matrix2d(Eigen::Vector2d(0.04, 0.05).asDiagonal()));
  add(25, 1.0, 20, true, std::nullopt);
  add(25, 1.0, 30, true, std::nullopt);
  add(25, 2.0, 9, true, Eigen::Matrix2d(Eigen::Vector2d(1.0, 3.0).asDiagonal()));
  add(5, 5.0, 2, true, std::nullopt);
  add(25, 5.0, 20, false, std::nullopt);
  add(45, 0.1, 20, true, std::nullopt);
  const std::vector<VelocityBin> bins = velocityErrorByRange(pairs, 10.0, 5, 1000, 2);
  ASSERT_EQ(bins.size(), 2u);
  EXPECT_DOUBLE_EQ(bins[0].from, 0.0);
  EXPECT_DOUBLE_EQ(bins[0].to, 10.0);
  EXPECT_EQ(bins[0].pairs, 3);
  EXPECT_NEAR(bins[0].rmse_mps, 0.3, 1e-12);
  EXPECT_NEAR(*bins[0].own_rms_mps, 0.3, 1e-12);
  EXPECT_DOUBLE_EQ(bins[1].from, 20.0);
  EXPECT_EQ(bins[1].pairs, 3);
  EXPECT_NEAR(bins[1].rmse_mps, std::sqrt(6.0 / 3), 1e-12);
  EXPECT_NEAR(*bins[1].own_rms_mps, 2.0, 1e-12);  // only the pair with a covariance
  // The young pair alone, and no covariance to predict it.
  const std::vector<VelocityBin> young = velocityErrorByRange(pairs, 10.0, 0, 4, 1);
  ASSERT_EQ(young.size(), 1u);
  EXPECT_NEAR(young[0].rmse_mps, 5.0, 1e-12);
  EXPECT_FALSE(young[0].own_rms_mps);
  // By age with the last bin at 10: age 2 (the young pair), 9, and 10 holding ages 20 and 30.
  const std::vector<VelocityBin> ages = velocityErrorByAge(pairs, 10, 1);
  ASSERT_EQ(ages.size(), 3u);
  EXPECT_DOUBLE_EQ(ages[0].from, 2.0);
  EXPECT_DOUBLE_EQ(ages[1].from, 9.0);
  EXPECT_NEAR(ages[1].rmse_mps, 2.0, 1e-12);
  EXPECT_DOUBLE_EQ(ages[2].from, 10.0);
  EXPECT_EQ(ages[2].pairs, 6);  // three at 5 m, two at 25 m, one at 45 m; the parked car's never
  EXPECT_NEAR(ages[2].rmse_mps, std::sqrt((3 * 0.09 + 2 * 1.0 + 0.01) / 6), 1e-12);
  EXPECT_NEAR(*ages[2].own_rms_mps, 0.3, 1e-12);
}
