// The track lifecycle (tentative -> confirmed -> coasting -> ended, with a confidence) and the
// per-class policy of the associator: score thresholds, untracked types, duplicate boxes from two
// class files, and gates that keep pedestrians walking side by side apart.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>

#include "dlslot/track_lifecycle.hpp"
#include "trajectory_associator.hpp"

using namespace dlslot;
using namespace dlslot::tracker;

namespace {

constexpr double kDt = 0.1;

Box box(double x, double y, const std::string& type, double score = 5.0) {
  Box b;
  b.center << x, y, -0.8;
  b.size = type == "Pedestrian" ? Eigen::Vector3d(0.8, 0.6, 1.7) : Eigen::Vector3d(4.2, 1.8, 1.5);
  b.type = type;
  b.score = score;
  return b;
}

FrameAssociations step(TrajectoryAssociator& a, int frame, const std::vector<Box>& boxes) {
  return a.associate(frame, frame * kDt, Pose::Identity(), boxes);
}

ClassPolicy policy(int min_hits, int max_misses) {
  ClassPolicy p;
  p.name = "car";
  p.types = {"Car"};
  p.min_hits = min_hits;
  p.max_misses = max_misses;
  return p;
}

}  // namespace

TEST(TrackLifecycle, TentativeConfirmedCoastingEnded) {
  const ClassPolicy p = policy(3, 2);
  TrackLifecycle life(0.9, p);
  EXPECT_EQ(life.status(), TrackStatus::Tentative);
  life.hit(0.9, 2, p);
  EXPECT_EQ(life.status(), TrackStatus::Tentative);
  const double tentative = life.confidence();
  life.hit(0.9, 3, p);  // 3 hits in the window
  EXPECT_EQ(life.status(), TrackStatus::Confirmed);
  EXPECT_GT(life.confidence(), tentative);  // confirmation ranks it above a tentative track
  EXPECT_NEAR(life.confidence(), 0.9, 1e-12);  // always detected, all at 0.9
  life.miss();
  EXPECT_EQ(life.status(), TrackStatus::Coasting);
  EXPECT_NEAR(life.confidence(), 0.9 * 0.8, 1e-12);  // hit ratio's exponential mean: 1 -> 0.8
  EXPECT_FALSE(life.ended(p));
  life.miss();
  EXPECT_FALSE(life.ended(p));
  life.miss();
  EXPECT_TRUE(life.ended(p));  // more than max_misses in a row
  life.hit(0.9, 4, p);          // a detection again (had it not ended): confirmed, misses reset
  EXPECT_EQ(life.status(), TrackStatus::Confirmed);
  EXPECT_EQ(life.misses(), 0);
}

TEST(TrackLifecycle, MinHitsOneConfirmsAtOnceAndScoresMapToConfidence) {
  EXPECT_EQ(TrackLifecycle(0.5, policy(1, 2)).status(), TrackStatus::Confirmed);
  EXPECT_NEAR(detectionConfidence(0.0, ScoreScale::Logit), 0.5, 1e-12);
  EXPECT_NEAR(detectionConfidence(std::log(3.0), ScoreScale::Logit), 0.75, 1e-12);
  EXPECT_EQ(detectionConfidence(1.7, ScoreScale::Probability), 1.0);
  EXPECT_EQ(detectionConfidence(std::nan(""), ScoreScale::Logit), 0.0);
  EXPECT_THROW(scoreScaleFromName("softmax"), std::invalid_argument);
}

TEST(TrackerPolicy, AssociationsCarryTheLifecycle) {
  AssociatorConfig cfg;
  cfg.classes[0].min_hits = 3;
  TrajectoryAssociator a(cfg);
  std::vector<TrackStatus> seen;
  for (int f = 0; f < 4; ++f) seen.push_back(step(a, f, {box(10 + 0.5 * f, 0, "Car")}).associations[0].status);
  EXPECT_EQ(seen, (std::vector<TrackStatus>{TrackStatus::Tentative, TrackStatus::Tentative, TrackStatus::Confirmed,
                                            TrackStatus::Confirmed}));
  // Seen again after two misses: still the same, confirmed track.
  step(a, 4, {});
  step(a, 5, {});
  const Association r = step(a, 6, {box(13.0, 0, "Car")}).associations[0];
  EXPECT_EQ(r.track_id, 0);
  EXPECT_EQ(r.status, TrackStatus::Confirmed);
}

TEST(TrackerPolicy, ScoreThresholdAndUntrackedTypesAreCountedNotTracked) {
  AssociatorConfig cfg;
  cfg.classes[0].min_score = 2.0;  // car
  TrajectoryAssociator a(cfg);
  const FrameAssociations r =
      step(a, 0, {box(10, 0, "Car", 1.9), box(20, 0, "Car", 2.0), box(30, 0, "Tram"), box(5, 5, "Pedestrian", -3)});
  ASSERT_EQ(r.associations.size(), 2u);
  EXPECT_EQ(r.associations[0].detection_index, 1);  // the car at the threshold
  EXPECT_EQ(r.associations[1].detection_index, 3);  // pedestrians have no threshold here
  EXPECT_EQ(r.skipped.below_score, 1);
  EXPECT_EQ(r.skipped.untracked_type, 1);
  EXPECT_EQ(r.skipped.total(), 2);
}

TEST(TrackerPolicy, DuplicatesFromTwoClassFilesKeepTheMoreConfidentBox) {
  TrajectoryAssociator a;
  // A car box (score 6) and a pedestrian box centred inside it (score 1): one object.
  const FrameAssociations r = step(a, 0, {box(10, 0, "Pedestrian", 1.0), box(10.5, 0.3, "Car", 6.0),
                                          box(10, 2.5, "Pedestrian", 1.0)});  // beside the car: kept
  ASSERT_EQ(r.associations.size(), 2u);
  EXPECT_EQ(r.associations[0].detection_index, 1);
  EXPECT_EQ(r.associations[1].detection_index, 2);
  EXPECT_EQ(r.skipped.duplicate, 1);
}

TEST(TrackerPolicy, GateIsAnisotropicInThePredictedMotionsFrame) {
  // A car driving along +x at 10 m/s, tracked long enough to be fitted. A detection 1.5 m ahead
  // of the prediction is inside the gate (along axis 2 m); 1.5 m to the side is not (across 1 m).
  AssociatorConfig cfg;
  cfg.classes[0].gate_along_m = 2.0;
  cfg.classes[0].gate_across_m = 1.0;
  cfg.classes[0].gate_growth_mps = 0.0;
  for (const auto& [dx, dy, same] : {std::tuple{1.5, 0.0, true}, std::tuple{0.0, 1.5, false}}) {
    TrajectoryAssociator a(cfg);
    for (int f = 0; f < 6; ++f) step(a, f, {box(1.0 * f, 0, "Car")});
    const Association r = step(a, 6, {box(6.0 + dx, dy, "Car")}).associations[0];
    EXPECT_EQ(r.track_id == 0, same) << dx << " " << dy;
  }
}

// Six pedestrians walking together in two rows, 0.8-1.0 m apart, at 1.4 m/s with 0.12 m box noise
// (as much as they move in a frame) and 15 % misses. Counts identity switches and associations.
int crowdIdentitySwitches(const AssociatorConfig& cfg, unsigned seed, int* associations) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.12);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const std::vector<Eigen::Vector2d> offsets = {{0, 0}, {0, 0.8}, {0, 1.6}, {0.9, 0.35}, {0.9, 1.15}, {0.9, 1.95}};
  TrajectoryAssociator a(cfg);
  std::map<int, int> last_id;  // person -> track id
  int switches = 0;
  for (int f = 0; f < 80; ++f) {
    std::vector<Box> dets;
    std::vector<int> who;
    for (int i = 0; i < static_cast<int>(offsets.size()); ++i) {
      if (u(rng) < 0.15) continue;
      const Eigen::Vector2d p = offsets[i] + Eigen::Vector2d(1.4 * f * kDt, 0.3 * std::sin(0.05 * f));
      dets.push_back(box(p.x() + noise(rng), p.y() + noise(rng), "Pedestrian"));
      who.push_back(i);
    }
    const FrameAssociations r = step(a, f, dets);
    *associations += static_cast<int>(r.associations.size());
    for (const Association& as : r.associations) {
      const int person = who[as.detection_index];
      auto it = last_id.find(person);
      if (it != last_id.end() && it->second != as.track_id) ++switches;
      last_id[person] = as.track_id;
    }
  }
  return switches;
}

// The pedestrian policy (a line, 1 m gates) keeps 99 % of the identities; the car's settings for
// every class (eq. 3's cubic, 4 m gates, as the tracker had before per-class policies) lose them.
TEST(TrackerPolicy, PedestriansInACrowdKeepTheirIdentities) {
  int with_policy = 0, with_car_settings = 0, associations = 0, unused = 0;
  AssociatorConfig car_like;
  ClassPolicy& ped = car_like.classes[1];
  ped.gate_across_m = ped.gate_along_m = ped.young_gate_m = 4.0;
  ped.max_polynomial_degree = 3;
  for (unsigned seed = 1; seed <= 10; ++seed) {
    with_policy += crowdIdentitySwitches(AssociatorConfig{}, seed, &associations);
    with_car_settings += crowdIdentitySwitches(car_like, seed, &unused);
  }
  std::printf("crowd: %d associations, identity switches: pedestrian policy %d, car settings %d\n", associations,
              with_policy, with_car_settings);
  EXPECT_LT(with_policy * 100, associations);
  EXPECT_GT(with_car_settings, 10 * std::max(1, with_policy));
}

TEST(TrackerPolicy, WeakDetectionsOnlyExtendConfirmedTracks) {
  AssociatorConfig cfg;
  cfg.classes[0].min_score = 3.0;
  cfg.classes[0].min_score_to_extend = 0.0;
  cfg.classes[0].min_hits = 2;
  TrajectoryAssociator a(cfg);
  // A weak box alone starts nothing (counted as below score); one under min_score_to_extend is not tracked.
  FrameAssociations r = step(a, 0, {box(10, 0, "Car", 1.0), box(30, 0, "Car", -1.0)});
  EXPECT_TRUE(r.associations.empty());
  EXPECT_EQ(r.skipped.below_score, 2);
  // A strong box starts a track; confirmed at its second strong box; then a weak box extends it.
  step(a, 1, {box(20, 0, "Car", 5.0)});
  step(a, 2, {box(20.5, 0, "Car", 5.0)});
  r = step(a, 3, {box(21.0, 0, "Car", 1.0)});
  ASSERT_EQ(r.associations.size(), 1u);
  EXPECT_EQ(r.associations[0].track_id, 0);
  EXPECT_EQ(r.associations[0].status, TrackStatus::Confirmed);
  // A weak box near a tentative track does not join it.
  step(a, 4, {box(21.5, 0, "Car", 5.0), box(-20, 0, "Car", 5.0)});
  r = step(a, 5, {box(-20, 0.2, "Car", 1.0)});
  EXPECT_TRUE(r.associations.empty());
  cfg.classes[0].min_score_to_extend = 4.0;  // above min_score: refused
  EXPECT_THROW(TrajectoryAssociator{cfg}, std::invalid_argument);
}
