// The message guard (common/include/dlslot/message_guard.hpp): its layout walk agrees with
// lcm-gen's encoder byte for byte, every malformed variant is refused with the right
// reason (never thrown, never allocated for), and FrameOrder's duplicate/old/jump rules (no resync).
#include <gtest/gtest.h>

#include "message_samples.hpp"

using namespace dlslot;
using namespace dlslot::test;

namespace {

template <class Msg>
Refusal check(const Bytes& b) {
  Msg m;
  return decodeChecked(b.data(), b.size(), &m);
}

// Every prefix of a valid encoding is refused as truncated (or, shorter than the fingerprint,
// as truncated too), and the full one is accepted.
template <class Msg>
void expectLayoutMatches(const Msg& sample) {
  const Bytes b = encode(sample);
  Msg out;
  const Refusal ok = decodeChecked(b.data(), b.size(), &out);
  EXPECT_FALSE(ok) << Msg::getTypeName() << ": " << ok.reason << ": " << ok.detail;
  for (size_t n = 0; n < b.size(); ++n) {
    const Refusal r = check<Msg>(Bytes(b.begin(), b.begin() + n));
    EXPECT_TRUE(r) << Msg::getTypeName() << " cut to " << n << " bytes was accepted";
  }
  Bytes longer = b;
  longer.push_back(0);
  EXPECT_EQ(check<Msg>(longer).reason, "trailing_bytes") << Msg::getTypeName();
}

template <class Msg>
void expectStructuralRefusals(const Msg& sample, size_t string_at, size_t string_length, size_t count_at = 0,
                              int32_t count = 0) {
  const Bytes b = encode(sample);
  if (string_at) {
    ASSERT_EQ(getI32(b, string_at), static_cast<int32_t>(string_length + 1)) << Msg::getTypeName();
  }
  ASSERT_EQ(getI32(b, count_at ? count_at : b.size() - 4), count) << Msg::getTypeName() << ": count not where expected";
  for (const Malformed& m : structuralVariants(b, string_at, count_at)) {
    const Refusal r = check<Msg>(m.bytes);
    ASSERT_TRUE(r) << Msg::getTypeName() << " " << m.name << " accepted";
    std::string expected;
    if (m.name.rfind("count", 0) == 0) expected = "bad_count";
    if (m.name.rfind("string", 0) == 0) expected = "bad_string";
    if (m.name == "truncated") expected = "truncated";
    if (!expected.empty()) {
      EXPECT_EQ(r.reason, expected) << Msg::getTypeName() << " " << m.name << ": " << r.detail;
    }
  }
}

template <class Msg>
void expectFrameRefusals(const Msg& sample) {
  for (const Malformed& m : frameVariants(encode(sample))) {
    const Refusal r = check<Msg>(m.bytes);
    EXPECT_EQ(r.reason, "frame_range") << Msg::getTypeName() << " " << m.name << ": " << r.detail;
  }
}

}  // namespace

TEST(MessageGuard, LayoutWalkConsumesExactlyWhatLcmGenEncodes) {
  expectLayoutMatches(sampleScan(4));
  point_cloud_t scan = sampleScan(4);
  scan.x = scan.y = scan.z = scan.intensity = {1.f, 2.f, 3.f};
  scan.num_points = 3;
  expectLayoutMatches(scan);
  detections_t det = sampleDetections(4);
  det.boxes = {sampleBox(-1), sampleBox(-1)};
  det.num_boxes = 2;
  expectLayoutMatches(det);
  expectLayoutMatches(sampleGroundTruth(4));
  odometry_t odo = sampleOdometry(4);
  odo.timings = {sampleTiming(), sampleTiming()};
  odo.num_timings = 2;
  expectLayoutMatches(odo);
  expectLayoutMatches(sampleAssociations(4));
  slot_state_t slot = sampleSlotState(4);
  slot.timings = {sampleTiming()};
  slot.num_timings = 1;
  expectLayoutMatches(slot);
  process_status_t status = sampleStatus();
  status.counter_names = {"a", "bc"};
  status.counter_values = {1, 2};
  status.num_counters = 2;
  expectLayoutMatches(status);
  expectLayoutMatches(sampleMapState(4, /*with_loops=*/true));
}

TEST(MessageGuard, CountsAndStringLengthsAreCheckedBeforeLcmGenAllocates) {
  expectStructuralRefusals(sampleScan(4), kScanStringAt, 4);
  expectStructuralRefusals(sampleDetections(4), kDetectionsSourceAt, 9, kDetectionsCountAt, 0);
  expectStructuralRefusals(sampleDetectionsWithBox(4), kDetectionsStringAt, 3, kDetectionsCountAt, 1);
  expectStructuralRefusals(sampleGroundTruth(4), kGroundTruthStringAt, 3);
  expectStructuralRefusals(sampleOdometry(4), kOdometryStringAt, 2);
  expectStructuralRefusals(sampleAssociations(4), kAssociationsStringAt, 8);
  expectStructuralRefusals(sampleSlotState(4), kSlotStringAt, 4, slotStateTimingsCountAt(encode(sampleSlotState(4))));
  expectStructuralRefusals(sampleStatus(), kStatusStringAt, 8);
  expectStructuralRefusals(sampleMapState(4), 0, 0);
  // A NUL inside a string, or none at its end (lcm-gen would not encode it back).
  Bytes b = encode(sampleScan(4));
  b[kScanStringAt + 4 + 1] = 0;
  EXPECT_EQ(check<point_cloud_t>(b).reason, "bad_string");
  b = encode(sampleScan(4));
  b[kScanStringAt + 4 + 4] = 'x';
  EXPECT_EQ(check<point_cloud_t>(b).reason, "bad_string");
  // Another type's fingerprint.
  EXPECT_EQ(check<odometry_t>(encode(sampleScan(1))).reason, "fingerprint");
}

TEST(MessageGuard, FramesOutsideTheSequenceRangeAreRefused) {
  expectFrameRefusals(sampleScan(4));
  expectFrameRefusals(sampleDetections(4));
  expectFrameRefusals(sampleGroundTruth(4));
  expectFrameRefusals(sampleOdometry(4));
  expectFrameRefusals(sampleAssociations(4));
  expectFrameRefusals(sampleSlotState(4));
  expectFrameRefusals(sampleMapState(4, true));
  EXPECT_EQ(check<odometry_t>(encode(sampleOdometry(-1))).reason, "frame_range");
  EXPECT_FALSE(check<odometry_t>(encode(sampleOdometry(kMaxFrame))));
}

TEST(MessageGuard, WellFormedLiesAreRefused) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(check<odometry_t>(nanPose(encode(sampleOdometry(2)), kOdometryPoseAt).bytes).reason, "non_finite");
  EXPECT_EQ(check<slot_state_t>(nanPose(encode(sampleSlotState(2)), kSlotPoseAt).bytes).reason, "non_finite");
  EXPECT_EQ(check<associations_t>(nanPose(encode(sampleAssociations(2)), kAssociationsPoseAt).bytes).reason, "non_finite");
  EXPECT_EQ(check<ground_truth_t>(nanPose(encode(sampleGroundTruth(2)), kGroundTruthPoseAt).bytes).reason, "non_finite");
  EXPECT_EQ(check<map_state_t>(nanPose(encode(sampleMapState(2)), kMapStatePoseAt).bytes).reason, "non_finite");
  // A loop must join this scan or an earlier one to an older one; its scores are finite and >= 0.
  map_state_t map = sampleMapState(5, true);
  EXPECT_FALSE(check<map_state_t>(encode(map)));
  map.loops[0].match_frame = 5;
  EXPECT_EQ(check<map_state_t>(encode(map)).reason, "frame_range");
  map = sampleMapState(5, true);
  map.loops[1].query_frame = 6;
  EXPECT_EQ(check<map_state_t>(encode(map)).reason, "frame_range");
  map = sampleMapState(5, true);
  map.loops[1].inlier_ratio = nan;
  EXPECT_EQ(check<map_state_t>(encode(map)).reason, "bad_value");
  map = sampleMapState(5, true);
  map.keyframes = -1;
  EXPECT_EQ(check<map_state_t>(encode(map)).reason, "bad_value");

  odometry_t odo = sampleOdometry(2);
  odo.pose.orientation[0] = 0;  // not a rotation
  EXPECT_EQ(check<odometry_t>(encode(odo)).reason, "bad_quaternion");
  odo = sampleOdometry(2);
  odo.covariance[35] = std::numeric_limits<double>::infinity();
  EXPECT_EQ(check<odometry_t>(encode(odo)).reason, "non_finite");
  odo = sampleOdometry(2);
  odo.status = 9;
  EXPECT_EQ(check<odometry_t>(encode(odo)).reason, "bad_enum");

  slot_state_t slot = sampleSlotState(2);
  slot.tracks[0].size[1] = -1;
  EXPECT_EQ(check<slot_state_t>(encode(slot)).reason, "bad_size");
  slot = sampleSlotState(2);
  slot.tracks[0].confidence = 1.5;
  EXPECT_EQ(check<slot_state_t>(encode(slot)).reason, "bad_value");
  slot = sampleSlotState(2);
  slot.tracks[0].confidence = nan;
  EXPECT_EQ(check<slot_state_t>(encode(slot)).reason, "bad_value");
  slot = sampleSlotState(2);
  slot.tracks[0].status = 3;
  EXPECT_EQ(check<slot_state_t>(encode(slot)).reason, "bad_enum");
  slot = sampleSlotState(2);
  slot.has_smoothed = true;
  slot.smoothed_frame = 5;  // after the frame itself
  EXPECT_EQ(check<slot_state_t>(encode(slot)).reason, "frame_range");

  associations_t assoc = sampleAssociations(2);
  assoc.associations[0].status = -1;
  EXPECT_EQ(check<associations_t>(encode(assoc)).reason, "bad_enum");
  assoc = sampleAssociations(2);
  assoc.associations[0].confidence = -0.1;
  EXPECT_EQ(check<associations_t>(encode(assoc)).reason, "bad_value");

  ground_truth_t gt = sampleGroundTruth(2);
  gt.boxes[0].size[2] = 0;
  EXPECT_EQ(check<ground_truth_t>(encode(gt)).reason, "bad_size");
  gt = sampleGroundTruth(2);
  gt.dontcare = {sampleBox(-1)};
  gt.dontcare[0].size[0] = gt.dontcare[0].size[1] = gt.dontcare[0].size[2] = 0;  // DontCare may have no extent
  gt.num_dontcare = 1;
  EXPECT_FALSE(check<ground_truth_t>(encode(gt)));

  point_cloud_t scan = sampleScan(2);
  scan.x = scan.y = scan.z = scan.intensity = {1.f};
  scan.num_points = 1;
  Bytes b = encode(scan);
  putF32(b, b.size() - 16, std::numeric_limits<float>::quiet_NaN());  // x[0]
  EXPECT_EQ(check<point_cloud_t>(b).reason, "non_finite");

  process_status_t status = sampleStatus();
  status.time_mean_ms = nan;
  EXPECT_EQ(check<process_status_t>(encode(status)).reason, "non_finite");
  status = sampleStatus();
  status.name.clear();
  EXPECT_EQ(check<process_status_t>(encode(status)).reason, "bad_value");
}

TEST(MessageGuard, FrameOrderRefusesDuplicatesOldAndFarFramesAndNeverResyncs) {
  FrameOrder o;
  EXPECT_FALSE(o.accept(5));
  EXPECT_FALSE(o.accept(6));
  EXPECT_EQ(o.accept(6).reason, "duplicate_frame");
  EXPECT_EQ(o.accept(4).reason, "old_frame");
  EXPECT_FALSE(o.accept(9));  // a gap is not a refusal
  EXPECT_EQ(o.accept(9 + kMaxFrameJump + 1).reason, "frame_jump");
  EXPECT_EQ(o.accept(std::numeric_limits<int>::max()).reason, "frame_range");
  EXPECT_EQ(o.last(), 9);
  EXPECT_FALSE(o.accept(10));
  // Old frames in a row, however many, never make the channel follow them (replayed frames 0, 1,
  // 2 once made it resync and reset the nodes)...
  for (int f = 0; f < 10; ++f) EXPECT_EQ(o.accept(f).reason, "old_frame") << f;
  // ...nor do far frames in a row (frames 2001-2004 once took over a channel at frame 12).
  for (int f = 2001; f < 2010; ++f) EXPECT_EQ(o.accept(f).reason, "frame_jump") << f;
  for (int i = 0; i < 5; ++i) EXPECT_EQ(o.accept(10).reason, "duplicate_frame");
  EXPECT_EQ(o.last(), 10);
  EXPECT_FALSE(o.accept(11));
  // Only an explicit restart (the player's start event) begins a new numbering.
  o.reset();
  EXPECT_FALSE(o.accept(0));
  EXPECT_EQ(o.last(), 0);
}

TEST(MessageGuard, BoxesAreCheckedBeforeAnythingElseSeesThem) {
  // A NaN box centre, a size <= 0: the whole DETECTIONS / ASSOCIATIONS message is refused.
  detections_t det = sampleDetectionsWithBox(500);
  det.boxes[0].center[0] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(check<detections_t>(encode(det)).reason, "non_finite");
  det = sampleDetectionsWithBox(500);
  det.boxes[0].size[1] = 0;
  EXPECT_EQ(check<detections_t>(encode(det)).reason, "bad_size");
  det = sampleDetectionsWithBox(500);
  det.boxes[0].size[2] = -1;
  EXPECT_EQ(check<detections_t>(encode(det)).reason, "bad_size");
  det = sampleDetectionsWithBox(500);
  det.boxes[0].score = std::numeric_limits<double>::infinity();
  EXPECT_EQ(check<detections_t>(encode(det)).reason, "non_finite");
  EXPECT_FALSE(check<detections_t>(encode(sampleDetectionsWithBox(500))));
  associations_t a = sampleAssociations(3);
  a.associations[0].box_world.yaw = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(check<associations_t>(encode(a)).reason, "non_finite");
  a = sampleAssociations(3);
  a.associations[0].box_lidar.size[0] = 0;
  EXPECT_EQ(check<associations_t>(encode(a)).reason, "bad_size");
}
