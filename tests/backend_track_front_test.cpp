// A vehicle track's front (track_front.hpp): its motion once it is fast enough to say, else the
// majority of its detections, against known answers.
#include <gtest/gtest.h>

#include <cmath>

#include "backend/track_front.hpp"

using namespace dlslot::backend;

TEST(BackendTrackFront, HeadingsAgreeWithin90Degrees) {
  EXPECT_TRUE(headingsAgree(0.1, -0.1));
  EXPECT_TRUE(headingsAgree(M_PI - 0.1, -M_PI + 0.1));  // 0.2 rad apart across the wrap
  EXPECT_FALSE(headingsAgree(0.0, M_PI));
  EXPECT_FALSE(headingsAgree(1.0, 1.0 - M_PI / 2 - 0.01));
  EXPECT_TRUE(headingsAgree(1.0, 1.0 - M_PI / 2 + 0.01));
}

TEST(BackendTrackFront, TheMajorityOfDetectionsDecidesASlowTrack) {
  // Born from a box turned round (heading pi): its first detection agrees with it by definition,
  // the next ones (heading ~0, the car's front) do not.
  TrackFront f = withDetection(TrackFront{}, M_PI, M_PI);
  EXPECT_EQ(f.agree, 1);
  EXPECT_EQ(f.disagree, 0);
  EXPECT_FALSE(turned(f));
  f = withDetection(f, 0.05, M_PI);
  EXPECT_FALSE(turned(f)) << "a tie keeps the track's heading";
  f = withDetection(f, -0.03, M_PI);
  EXPECT_EQ(f.disagree, 2);
  EXPECT_TRUE(turned(f));
  // Slow motion (2 m/s, backwards along the track's heading) does not decide.
  f = withMotion(f, Eigen::Vector2d(2.0, 0.0), Eigen::Vector2d(-1.0, 0.0));
  EXPECT_FALSE(f.motion_turned.has_value());
  EXPECT_TRUE(turned(f));
}

TEST(BackendTrackFront, MotionDecidesOnceFastAndIsKeptWhileSlow) {
  // Every detection agrees with the track (a detector that turns this car for good) ...
  TrackFront f;
  for (int k = 0; k < 5; ++k) f = withDetection(f, M_PI + 0.01 * k, M_PI);
  EXPECT_FALSE(turned(f));
  // ... but the car moves along +x at 8 m/s while the track heads -x: it heads where it goes.
  f = withMotion(f, Eigen::Vector2d(8.0, 0.5), Eigen::Vector2d(-1.0, 0.0));
  ASSERT_TRUE(f.motion_turned.has_value());
  EXPECT_TRUE(turned(f));
  // Stopped at a light: the motion's word holds, whatever the detections say.
  f = withMotion(f, Eigen::Vector2d(0.2, 0.0), Eigen::Vector2d(-1.0, 0.0));
  for (int k = 0; k < 3; ++k) f = withDetection(f, M_PI, M_PI);
  EXPECT_TRUE(turned(f));
  // Moving again along its heading: not turned.
  f = withMotion(f, Eigen::Vector2d(-4.0, 0.0), Eigen::Vector2d(-1.0, 0.0));
  EXPECT_FALSE(turned(f));
}
