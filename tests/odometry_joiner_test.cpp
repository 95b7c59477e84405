// Joining LIDAR_SCAN and DETECTIONS by frame, with a timeout (the node's input logic).
#include <gtest/gtest.h>

#include "odometry/scan_joiner.hpp"

namespace dlslot::odometry {
namespace {

PointCloud scanOf(int n) { return PointCloud::Zero(4, n); }
std::vector<Box> boxes(int n) { return std::vector<Box>(n); }

TEST(OdometryScanJoiner, ReleasesCompleteScansInOrder) {
  ScanJoiner j(1.0, true);
  EXPECT_TRUE(j.addDetections(0, boxes(2), 0.0));
  EXPECT_TRUE(j.release(0.0).empty());
  EXPECT_TRUE(j.addScan(0, 100, scanOf(5), 0.01));
  std::vector<JoinedScan> out = j.release(0.01);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].frame.index, 0);
  EXPECT_EQ(out[0].frame.utime, 100);
  EXPECT_EQ(out[0].frame.scan.cols(), 5);
  EXPECT_EQ(out[0].frame.detections.size(), 2u);
  EXPECT_TRUE(out[0].has_detections);
  EXPECT_EQ(j.lastReleased(), 0);
}

TEST(OdometryScanJoiner, ScanWithoutDetectionsWaitsForTheTimeout) {
  ScanJoiner j(0.5, true);
  j.addScan(3, 0, scanOf(1), 10.0);
  EXPECT_TRUE(j.release(10.4).empty());
  std::vector<JoinedScan> out = j.release(10.5);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_FALSE(out[0].has_detections);
  // Its detections arriving late are stale.
  EXPECT_FALSE(j.addDetections(3, boxes(1), 10.6));
  EXPECT_FALSE(j.addScan(3, 0, scanOf(1), 10.6));
}

TEST(OdometryScanJoiner, ALaterCompleteScanReleasesAnOlderIncompleteOne) {
  ScanJoiner j(5.0, true);
  j.addScan(1, 0, scanOf(1), 0.0);  // its DETECTIONS were lost
  j.addScan(2, 0, scanOf(1), 0.1);
  j.addDetections(2, boxes(0), 0.1);
  std::vector<JoinedScan> out = j.release(0.1);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].frame.index, 1);
  EXPECT_FALSE(out[0].has_detections);
  EXPECT_EQ(out[1].frame.index, 2);
  EXPECT_TRUE(out[1].has_detections);  // an empty box list is still the detector's answer
}

TEST(OdometryScanJoiner, DetectionsWithoutAScanAreDropped) {
  ScanJoiner j(0.5, true);
  j.addDetections(7, boxes(1), 0.0);
  EXPECT_TRUE(j.release(1.0).empty());
  EXPECT_EQ(j.lastReleased(), -1);
  j.addScan(8, 0, scanOf(1), 1.0);
  j.addDetections(8, boxes(1), 1.0);
  ASSERT_EQ(j.release(1.0).size(), 1u);
}

TEST(OdometryScanJoiner, UnfilteredModeDoesNotWait) {
  ScanJoiner j(10.0, false);
  j.addScan(0, 0, scanOf(1), 0.0);
  std::vector<JoinedScan> out = j.release(0.0);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_FALSE(out[0].has_detections);
}

TEST(OdometryScanJoiner, ResetForgetsEverything) {
  ScanJoiner j(1.0, true);
  j.addScan(5, 0, scanOf(1), 0.0);
  j.addDetections(5, boxes(1), 0.0);
  ASSERT_EQ(j.release(0.0).size(), 1u);
  j.reset();
  EXPECT_EQ(j.lastReleased(), -1);
  EXPECT_TRUE(j.addScan(0, 0, scanOf(1), 1.0));
}

}  // namespace
}  // namespace dlslot::odometry
