// The results files' score column (tracker::trackScore, writeTrackScores): known answers for the
// evidence of a track, its ranking, and the property the evaluators rely on: a mean of a track's
// equal rows, read back from the file, is the written value exactly (no drift from pass to pass).
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <random>

#include "track_evidence.hpp"

using namespace dlslot;
using namespace dlslot::tracker;

namespace {

ClassPolicy carPolicy(double floor) {
  ClassPolicy p;
  p.name = "car";
  p.types = {"Car"};
  p.min_hits = 2;
  p.min_score = 2.5;
  p.min_score_to_extend = floor;
  return p;
}

TrackEvidence evidence(const std::vector<std::pair<int, double>>& frames_scores) {
  TrackEvidence e;
  for (const auto& [f, s] : frames_scores) e.add(f, s);
  return e;
}

kitti::LabelRow carRow(int frame, int id) {
  kitti::LabelRow r;
  r.frame = frame;
  r.track_id = id;
  r.type = "Car";
  r.box.h = 1.5;
  r.box.w = 1.6;
  r.box.l = 3.9;
  r.box.bottom_center = Eigen::Vector3d(0, 1.6, 20);
  return r;
}

}  // namespace

TEST(TrackEvidence, MeanScoreWithMissesAtTheFloorShrunkByTheHitsToConfirm) {
  const ClassPolicy p = carPolicy(0.0);
  // Three detections of 6 in frames 10, 11, 13 (frame 12 missed): (18 + 0 * (1 + 2)) / (3 + 1 + 2).
  const TrackEvidence e = evidence({{10, 6.0}, {11, 6.0}, {13, 6.0}});
  EXPECT_EQ(e.hits, 3);
  EXPECT_EQ(e.missed(), 1);
  EXPECT_DOUBLE_EQ(trackScore(e, p), 3.0);
  // The floor is min_score_to_extend; without one (every detection tracked) it is 0 (even odds).
  EXPECT_DOUBLE_EQ(trackScore(e, carPolicy(1.0)), (18.0 + 1.0 * 3) / 6);
  ClassPolicy open = p;
  open.min_score_to_extend = open.min_score = -1e300;
  EXPECT_DOUBLE_EQ(evidenceFloor(open), 0.0);
}

TEST(TrackEvidence, LongConsistentTracksRankAboveShortOrFlickeringOnes) {
  const ClassPolicy p = carPolicy(0.0);
  std::vector<std::pair<int, double>> long_track, flicker;
  for (int f = 0; f < 20; ++f) long_track.push_back({f, 5.0});
  for (int f = 0; f < 20; f += 3) flicker.push_back({f, 5.0});
  const double l = trackScore(evidence(long_track), p);
  const double one = trackScore(evidence({{0, 8.0}}), p);  // a single confident detection
  const double fl = trackScore(evidence(flicker), p);
  EXPECT_GT(l, one);
  EXPECT_GT(l, fl);
  EXPECT_LT(l, 5.0);  // never above its detections' mean
}

TEST(TrackEvidence, ScoresAreDistinctAndTheirMeansExactAfterTheFileRoundTrip) {
  // Many tracks with random evidence and random lengths: every score distinct, and the mean of a
  // track's rows, as AB3DMOT's script computes it from the text file (summed in row order, then
  // again and again on the means), equals the written value to the bit.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> score(-3, 12);
  std::uniform_int_distribution<int> length(1, 300);
  const ClassPolicy p = carPolicy(0.0);
  std::map<int, TrackEvidence> ev;
  std::map<int, const ClassPolicy*> policy;
  std::vector<kitti::LabelRow> rows;
  for (int id = 0; id < 200; ++id) {
    const int n = length(rng);
    for (int f = 0; f < n; ++f) {
      ev[id].add(f, score(rng));
      rows.push_back(carRow(f, id));
    }
    policy[id] = &p;
  }
  ev[200].add(0, 4.0);  // two tracks with equal evidence still get distinct scores
  ev[201].add(0, 4.0);
  policy[200] = policy[201] = &p;
  for (int id : {200, 201}) rows.push_back(carRow(0, id));
  writeTrackScores(rows, ev, policy);
  const std::string path = (std::filesystem::temp_directory_path() / "tracker_evidence_test.txt").string();
  kitti::writeTrackingLabels(path, rows);
  const std::vector<kitti::LabelRow> back = kitti::readTrackingLabels(path);
  std::remove(path.c_str());
  ASSERT_EQ(back.size(), rows.size());
  std::map<int, std::vector<double>> by_track;
  for (const kitti::LabelRow& r : back) by_track[r.track_id].push_back(*r.score);
  std::set<double> seen;
  for (auto& [id, scores] : by_track) {
    const double written = scores.front();
    EXPECT_NEAR(written, trackScore(ev[id], p), 1e-6);
    EXPECT_TRUE(seen.insert(written).second) << "track " << id << " shares its score";
    for (int pass = 0; pass < 41; ++pass) {
      double sum = 0;
      for (double s : scores) sum += s;
      const double mean = sum / scores.size();
      ASSERT_EQ(mean, written) << "track " << id << " drifts at pass " << pass;
      for (double& s : scores) s = mean;
    }
  }
}

// Motion over ground as evidence (MotionEvidence): a walk of 2 m in 2 s counts; the same 2 m
// spread over 20 s (0.1 m/s: GPS/INS drift under a parked object's long track) does not; 0.8 m
// (under dynamic_displacement_m) does not; nothing counts without ego poses.
TEST(TrackEvidence, MotionCountsAboveTheStaticLineAtAWalkingPace) {
  ClassPolicy p = carPolicy(0.0);
  p.moving_evidence = 0.5;
  auto track = [](double metres, double seconds) {
    TrackEvidence e;
    const int n = static_cast<int>(seconds * 10) + 1;
    for (int f = 0; f < n; ++f) e.add(f, 3.0, Eigen::Vector3d(metres * f / (n - 1), 7, 0), 0.1 * f);
    return e;
  };
  MotionEvidence m;
  m.ego_poses_known = true;
  m.moved_m = 1.0;
  const TrackEvidence walk = track(2.0, 2.0), drift = track(2.0, 20.0), shuffle = track(0.8, 1.0);
  EXPECT_NEAR(walk.displacement(), 2.0, 1e-12);
  EXPECT_NEAR(walk.duration(), 2.0, 1e-12);
  EXPECT_TRUE(m.moved(walk));
  EXPECT_FALSE(m.moved(drift));
  EXPECT_FALSE(m.moved(shuffle));
  EXPECT_DOUBLE_EQ(trackScore(walk, p, m) - trackScore(walk, p), 0.5);
  EXPECT_DOUBLE_EQ(trackScore(drift, p, m), trackScore(drift, p));
  m.ego_poses_known = false;
  EXPECT_FALSE(m.moved(walk));
}
