// The KITTI tracking protocol (eval::evaluateKittiTracking): a hand-built sequence in which every
// rule of the devkit decides some rows, checked count by count; sAMOTA / AMOTA on a score sweep
// worked out by hand; AB3DMOT's drifting scores; several sequences pooled.
#include <gtest/gtest.h>

#include <cmath>

#include "kitti_protocol.hpp"

using namespace dlslot;
using eval::KittiClassMetrics;
using eval::KittiSequence;

namespace {

// A row in the camera frame: a car-sized box (pedestrian-sized for people) standing on y = 1.6 at
// (x, z), heading along the camera x axis, with a 2-D box 100 px tall unless given.
kitti::LabelRow row(int frame, int id, const std::string& type, double x, double z, double score = 1.0,
                    Eigen::Vector4d bbox2d = Eigen::Vector4d(600, 150, 700, 250)) {
  kitti::LabelRow r;
  r.frame = frame;
  r.track_id = id;
  r.type = type;
  const bool person = type == "Pedestrian" || type == "Person_sitting";
  r.box.h = person ? 1.7 : 1.5;
  r.box.w = person ? 0.6 : 1.6;
  r.box.l = person ? 0.8 : 3.9;
  r.box.bottom_center = Eigen::Vector3d(x, 1.6, z);
  r.box.rotation_y = 0;
  r.bbox2d = bbox2d;
  r.score = score;
  return r;
}

kitti::LabelRow dontCare(int frame, const Eigen::Vector4d& bbox2d) {
  kitti::LabelRow r;
  r.frame = frame;
  r.track_id = -1;
  r.type = "DontCare";
  r.truncated = -1;
  r.occluded = -1;
  r.bbox2d = bbox2d;
  r.box.h = r.box.w = r.box.l = -1;
  r.box.bottom_center = Eigen::Vector3d(-1000, -1000, -1000);
  return r;
}

// Frames 0..5. Every rule of the devkit decides some row (counts for the car class in brackets):
KittiSequence handBuilt() {
  KittiSequence s;
  s.name = "hand";
  for (int f = 0; f < 6; ++f) {
    // Car 1: tracked by 100 (frames 0-1), then by 101 (2, 3, 5), missed in frame 4:
    // one identity switch (frame 2), two fragmentations (frame 2, and the return in frame 5), one FN.
    s.labels.push_back(row(f, 1, "Car", 0, 20));
    if (f != 4) s.tracks.push_back(row(f, f < 2 ? 100 : 101, "Car", 0, 20, 5.0));
    // Car 2: truncated in frames 0-2 (ignored: its matches there are neither TP for MOTA nor FP),
    // tracked throughout by 200, 0.39 m off along its length: IoU 3.51 / 4.29.
    kitti::LabelRow car2 = row(f, 2, "Car", 6, 20);
    car2.truncated = f < 3 ? 1 : 0;
    s.labels.push_back(car2);
    s.tracks.push_back(row(f, 200, "Car", 6.39, 20, 5.0));
  }
  // Car 3: occlusion unknown (3), not tracked: ignored, not an FN.
  kitti::LabelRow car3 = row(0, 3, "Car", -6, 20);
  car3.occluded = 3;
  s.labels.push_back(car3);
  // Van 4 (the car class's neighbour), frames 0-1: matched by car track 400 in frame 0, missed in
  // frame 1: neither TP nor FP nor FN.
  s.labels.push_back(row(0, 4, "Van", -6, 30));
  s.labels.push_back(row(1, 4, "Van", -6, 30));
  s.tracks.push_back(row(0, 400, "Car", -6, 30, 5.0));
  // A Truck is not the car class's neighbour: a car track on it is a false positive (700).
  s.labels.push_back(row(0, 6, "Truck", 12, 30));
  s.tracks.push_back(row(0, 700, "Car", 12, 30, 5.0));
  // DontCare in frame 0: track 500 lies wholly inside it (ignored); track 501 a quarter inside (FP).
  s.labels.push_back(dontCare(0, {100, 100, 300, 200}));
  s.tracks.push_back(row(0, 500, "Car", 20, 40, 5.0, {150, 120, 250, 190}));
  s.tracks.push_back(row(0, 501, "Car", -20, 40, 5.0, {250, 100, 450, 200}));
  // Frame 1: an unmatched track 25 px tall is ignored (600), one 26 px tall is an FP (601).
  s.tracks.push_back(row(1, 600, "Car", 20, 40, 5.0, {500, 100, 540, 125}));
  s.tracks.push_back(row(1, 601, "Car", -20, 40, 5.0, {500, 100, 540, 126}));
  // Frame 2: an unmatched Van track is of the neighbour class: ignored (800).
  s.tracks.push_back(row(2, 800, "Van", 20, 40, 5.0));
  // People: pedestrian 5 tracked by 900 in frames 0-1; a Person_sitting tracked by a pedestrian
  // track (950) is ignored.
  for (int f = 0; f < 2; ++f) {
    s.labels.push_back(row(f, 5, "Pedestrian", 3, 10));
    s.tracks.push_back(row(f, 900, "Pedestrian", 3, 10, 5.0));
  }
  s.labels.push_back(row(0, 7, "Person_sitting", -3, 10));
  s.tracks.push_back(row(0, 950, "Pedestrian", -3, 10, 5.0));
  // Labels of other classes and tracks without an id take no part.
  s.labels.push_back(row(3, 8, "Misc", 0, 50));
  s.tracks.push_back(row(3, -1, "Car", 0, 50, 5.0));
  return s;
}

}  // namespace

TEST(KittiProtocol, EveryIgnoreRuleOfTheDevkitGivesItsKnownCount) {
  const auto m = eval::evaluateKittiTracking({handBuilt()});
  ASSERT_EQ(m.count("car"), 1u);
  ASSERT_EQ(m.count("pedestrian"), 1u);
  EXPECT_EQ(m.count("cyclist"), 0u);  // no cyclist labelled
  const eval::KittiCounts& car = m.at("car").all;
  EXPECT_EQ(car.labels, 9);          // car 1 six times, car 2 in frames 3-5
  EXPECT_EQ(car.ignored_labels, 6);  // car 2 truncated (3), car 3 occluded (1), the van (2)
  EXPECT_EQ(car.tp, 12);             // every match, the devkit's count: car 1 (5), car 2 (6), the van (1)
  EXPECT_EQ(car.fn, 1);              // car 1 in frame 4
  EXPECT_EQ(car.fp, 3);              // on the truck, a quarter in DontCare, 26 px tall
  EXPECT_EQ(car.ignored_tracks, 3);  // in DontCare, 25 px tall, the van track
  EXPECT_EQ(car.idsw, 1);
  EXPECT_EQ(car.frag, 2);
  ASSERT_TRUE(car.mota);
  EXPECT_NEAR(*car.mota, 1.0 - (1 + 3 + 1) / 9.0, 1e-12);
  ASSERT_TRUE(car.motp);
  EXPECT_NEAR(*car.motp, (6 * 1.0 + 6 * (3.51 / 4.29)) / 12, 1e-9);  // mean 3-D IoU of the matches

  const eval::KittiCounts& ped = m.at("pedestrian").all;
  EXPECT_EQ(ped.labels, 2);
  EXPECT_EQ(ped.ignored_labels, 1);  // the person sitting
  EXPECT_EQ(ped.tp, 3);
  EXPECT_EQ(ped.fp, 0);
  EXPECT_EQ(ped.fn, 0);
  EXPECT_EQ(ped.idsw, 0);
  EXPECT_DOUBLE_EQ(*ped.mota, 1.0);

  // HOTA scores what is left after the ignore rules: car 2's frames 0-2 and their track rows are gone.
  ASSERT_TRUE(m.at("car").hota);
  EXPECT_GT(m.at("car").hota->hota, 0.3);
  EXPECT_LT(m.at("car").hota->hota, 1.0);
  ASSERT_TRUE(m.at("pedestrian").hota);
  EXPECT_NEAR(m.at("pedestrian").hota->hota, 1.0, 1e-9);

  // A box the camera does not see never becomes a results row (kitti::resultRow), so it is
  // never scored: one behind the camera.
  kitti::Calib calib;
  calib.T_cam_velo.linear() << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  calib.P[2] << 700, 0, 600, 0, 0, 700, 180, 0, 0, 0, 1, 0;
  Box behind;
  behind.center << -20, 0, 0;
  behind.size << 3.9, 1.6, 1.5;
  EXPECT_FALSE(kitti::resultRow(0, behind, calib));
}

TEST(KittiProtocol, EachIdentitySwitchIsListedWithItsFrameAndTracks) {
  // The hand-built car 1 goes from track 100 to 101 in frame 2: the one switch, listed.
  const auto m = eval::evaluateKittiTracking({handBuilt()}).at("car");
  ASSERT_EQ(m.best_switches.size(), 1u);
  EXPECT_EQ(m.best_switches[0].sequence, "hand");
  EXPECT_EQ(m.best_switches[0].frame, 2);
  EXPECT_EQ(m.best_switches[0].label_id, 1);
  EXPECT_EQ(m.best_switches[0].from, 100);
  EXPECT_EQ(m.best_switches[0].to, 101);
}

TEST(KittiProtocol, SequencesArePooledAndKeepTheirOwnIds) {
  // Two copies of the hand-built sequence: every count doubles (the same label and track ids in the
  // second sequence are other objects: no switch between them), the ratios stay.
  const auto one = eval::evaluateKittiTracking({handBuilt()}).at("car").all;
  const auto two = eval::evaluateKittiTracking({handBuilt(), handBuilt()}).at("car").all;
  EXPECT_EQ(two.labels, 2 * one.labels);
  EXPECT_EQ(two.tp, 2 * one.tp);
  EXPECT_EQ(two.fp, 2 * one.fp);
  EXPECT_EQ(two.fn, 2 * one.fn);
  EXPECT_EQ(two.idsw, 2);
  EXPECT_EQ(two.frag, 4);
  EXPECT_NEAR(*two.mota, *one.mota, 1e-12);
}

TEST(KittiProtocol, OnlyTheGivenFramesAreScored) {
  KittiSequence s = handBuilt();
  s.frames = {0, 1, 2, 3};  // a run that covered four frames: car 1's miss in frame 4 is not there
  const auto car = eval::evaluateKittiTracking({s}).at("car").all;
  EXPECT_EQ(car.labels, 5);  // car 1 in frames 0-3, car 2 in frame 3
  EXPECT_EQ(car.fn, 0);
  EXPECT_EQ(car.idsw, 1);
  EXPECT_EQ(car.frag, 1);  // the switch in frame 2, followed by frame 3 tracked
}

TEST(KittiProtocol, AnIdTwiceInOneFrameIsRefusedLikeTheDevkitDoes) {
  KittiSequence s = handBuilt();
  s.tracks.push_back(row(2, 101, "Car", 30, 30));
  try {
    eval::evaluateKittiTracking({s});
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("sequence hand, frame 2: track id 101 appears twice"), std::string::npos)
        << e.what();
  }
}

// 40 cars in one frame, 20 of them tracked with scores 20, 19, ..., 1, and three false tracks
// scoring 18.5, 10.5 and 0.5. Each match raises recall by one recall point (1/40), so recall point
// i (1..19) gets the threshold 20 - i: i + 1 true tracks, FP_i = 0 (i = 1), 1 (i = 2..9) or 2
// (i = 10..19) false ones. MOTA_i = 1 - (39 - i + FP_i) / 40 and sMOTA_i = min(1, 1 - (FP_i - 1) / i).
TEST(KittiProtocol, SAmotaAndAmotaSweepTheScoresAtTheRecallPoints) {
  KittiSequence s;
  s.name = "sweep";
  for (int k = 0; k < 40; ++k) {
    const double x = -40 + 10 * (k % 8), z = 10 + 10 * (k / 8);
    s.labels.push_back(row(0, k, "Car", x, z));
    if (k < 20) s.tracks.push_back(row(0, 100 + k, "Car", x, z, 20.0 - k));
  }
  s.tracks.push_back(row(0, 200, "Car", 100, 100, 18.5));
  s.tracks.push_back(row(0, 201, "Car", 110, 100, 10.5));
  s.tracks.push_back(row(0, 202, "Car", 120, 100, 0.5));
  const KittiClassMetrics m = eval::evaluateKittiTracking({s}).at("car");
  EXPECT_EQ(m.all.tp, 20);
  EXPECT_EQ(m.all.fp, 3);
  EXPECT_EQ(m.all.fn, 20);
  EXPECT_NEAR(*m.all.mota, 1 - 23.0 / 40, 1e-12);

  double smota = 0, mota = 0;
  for (int i = 1; i <= 19; ++i) {
    const int fp = i == 1 ? 0 : i < 10 ? 1 : 2;
    mota += 1 - (39.0 - i + fp) / 40;
    smota += std::min(1.0, 1 - (fp - 1.0) / i);
  }
  EXPECT_EQ(m.sweep.recall_points_reached, 19);
  EXPECT_NEAR(*m.sweep.samota, smota / 40, 1e-9);
  EXPECT_NEAR(*m.sweep.amota, mota / 40, 1e-9);
  // The best single threshold keeps the 0.5 track out: MOTA 1 - 22 / 40 at score 1.
  ASSERT_TRUE(m.sweep.best_threshold);
  EXPECT_DOUBLE_EQ(*m.sweep.best_threshold, 1.0);
  EXPECT_NEAR(*m.sweep.best.mota, 1 - 22.0 / 40, 1e-12);
  // Whole-number scores average without rounding: AB3DMOT's script gives the same numbers.
  EXPECT_DOUBLE_EQ(*m.sweep_ab3dmot.samota, *m.sweep.samota);
  EXPECT_DOUBLE_EQ(*m.sweep_ab3dmot.amota, *m.sweep.amota);
}

TEST(KittiProtocol, TheScriptsDriftingMeanDropsATrackAtItsOwnThreshold) {
  // Ten rows of score v: the script's first mean x = (v + ... + v) / 10 ranks the track; averaged
  // again at each later pass it must stay below x (ten passes here).
  const auto again = [](double y) {
    double sum = 0;
    for (int i = 0; i < 10; ++i) sum += y;
    return sum / 10;
  };
  double v = 0;
  for (int k = 1; k < 100000 && v == 0; ++k) {
    const double c = 1.0 + k * 1e-4, x = again(c);
    bool below = true;
    double y = x;
    for (int pass = 0; pass < 10 && below; ++pass) below = (y = again(y)) < x;
    if (below) v = c;
  }
  ASSERT_GT(v, 0);
  // Cars A (track 1, mean score x) and B (track 2, score 0.5), ten frames each, no miss: the ranked
  // match scores (x ten times, 0.5 ten times, over 20 labels) give 19 recall points, the first 9 at
  // the threshold x (A kept, B not: MOTA 0.5), the other 10 at 0.5 (both: MOTA 1); every sMOTA is 1.
  KittiSequence s;
  s.name = "drift";
  for (int f = 0; f < 10; ++f) {
    s.labels.push_back(row(f, 1, "Car", 0, 20));
    s.labels.push_back(row(f, 2, "Car", 8, 20));
    s.tracks.push_back(row(f, 1, "Car", 0, 20, v));
    s.tracks.push_back(row(f, 2, "Car", 8, 20, 0.5));
  }
  const KittiClassMetrics m = eval::evaluateKittiTracking({s}).at("car");
  EXPECT_EQ(m.sweep.recall_points_reached, 19);
  EXPECT_NEAR(*m.sweep.samota, 19.0 / 40, 1e-12);
  EXPECT_NEAR(*m.sweep.amota, (9 * 0.5 + 10) / 40, 1e-12);
  // The script's mean of track 1 drifts below x: at its 9 thresholds nothing is kept (MOTA 0,
  // sMOTA 0), then both tracks are (MOTA 1, sMOTA 1).
  EXPECT_NEAR(*m.sweep_ab3dmot.samota, 10.0 / 40, 1e-12);
  EXPECT_NEAR(*m.sweep_ab3dmot.amota, 10.0 / 40, 1e-12);
}
