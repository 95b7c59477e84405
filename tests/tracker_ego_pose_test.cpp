// The tracker's ego pose for a scan (eq. 1's X_t) and the join of DETECTIONS with ODOMETRY.
#include <gtest/gtest.h>

#include "ego_pose_chain.hpp"

using namespace dlslot;
using namespace dlslot::tracker;

namespace {

Pose motion(double forward, double yaw) {
  Pose T = Pose::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() << forward, 0, 0;
  return T;
}

// Odometry that drifts: its own poses chain its deltas from the identity.
struct Odometry {
  std::vector<Pose> pose{Pose::Identity()}, delta{Pose::Identity()};
  Odometry(int n) {
    for (int i = 1; i < n; ++i) {
      delta.push_back(motion(1.0 + 0.1 * i, 0.02));
      pose.push_back(pose.back() * delta.back());
    }
  }
};

}  // namespace

TEST(TrackerEgoPose, OptimizedPoseOfTheScanWins) {
  EgoPoseChain chain;
  const Odometry odo(5);
  for (int f = 0; f < 5; ++f) chain.addOdometry(f, odo.pose[f], odo.delta[f]);
  const Pose X3 = motion(42, 0.3);
  chain.addOptimized(3, X3);
  const EgoPose e = chain.poseAt(3);
  EXPECT_EQ(e.source, PoseSource::Slot);
  EXPECT_TRUE(e.X.isApprox(X3));
}

TEST(TrackerEgoPose, LastOptimizedPoseChainedWithOdometry) {
  // Lockstep: SLOT_STATE of t-1 is there when scan t comes: X_t = X_{t-1} * T_{t-1}^t.
  EgoPoseChain chain;
  const Odometry odo(8);
  for (int f = 0; f < 8; ++f) chain.addOdometry(f, odo.pose[f], odo.delta[f]);
  const Pose X4 = motion(7, 0.1);
  chain.addOptimized(4, X4);
  EgoPose e = chain.poseAt(5);
  EXPECT_EQ(e.source, PoseSource::Odometry);
  EXPECT_TRUE(e.X.isApprox(X4 * odo.delta[5]));
  // The backend is two scans behind: both deltas are chained.
  e = chain.poseAt(6);
  EXPECT_TRUE(e.X.isApprox(X4 * odo.delta[5] * odo.delta[6]));
  EXPECT_STREQ(poseSourceName(e.source), "odometry");
}

TEST(TrackerEgoPose, WithoutBackendTheOdometryPose) {
  EgoPoseChain chain;
  EXPECT_EQ(chain.poseAt(0).source, PoseSource::Predicted);  // nothing known: identity
  EXPECT_TRUE(chain.poseAt(0).X.isApprox(Pose::Identity()));
  const Odometry odo(4);
  for (int f = 0; f < 4; ++f) chain.addOdometry(f, odo.pose[f], odo.delta[f]);
  const EgoPose e = chain.poseAt(3);
  EXPECT_EQ(e.source, PoseSource::Odometry);
  EXPECT_TRUE(e.X.isApprox(odo.pose[3]));
}

TEST(TrackerEgoPose, AScanTheOdometryNeverSawIsBridgedByItsPoses) {
  EgoPoseChain chain;
  const Odometry odo(6);
  for (int f : {0, 1, 2, 3, 5}) chain.addOdometry(f, odo.pose[f], odo.delta[f]);  // no scan 4
  const Pose X3 = motion(3, 0.2);
  chain.addOptimized(3, X3);
  const EgoPose e = chain.poseAt(5);
  EXPECT_EQ(e.source, PoseSource::Odometry);
  EXPECT_TRUE(e.X.isApprox(X3 * odo.pose[3].inverse() * odo.pose[5]));
  EXPECT_TRUE(e.X.isApprox(X3 * odo.delta[4] * odo.delta[5]));
}

TEST(TrackerEgoPose, MissingOdometryRepeatsTheLastMotion) {
  EgoPoseChain chain;
  const Odometry odo(6);
  for (int f = 0; f < 4; ++f) chain.addOdometry(f, odo.pose[f], odo.delta[f]);
  chain.addOptimized(2, odo.pose[2]);
  const EgoPose e = chain.poseAt(5);  // deltas 4 and 5 missing: delta 3 used twice
  EXPECT_EQ(e.source, PoseSource::Predicted);
  EXPECT_TRUE(e.X.isApprox(odo.pose[2] * odo.delta[3] * odo.delta[3] * odo.delta[3]));
}

TEST(TrackerEgoPose, ForgettingKeepsWhatTheChainNeeds) {
  EgoPoseChain chain;
  const Odometry odo(30);
  for (int f = 0; f < 30; ++f) {
    chain.addOdometry(f, odo.pose[f], odo.delta[f]);
    if (f >= 1) chain.addOptimized(f - 1, odo.pose[f - 1]);
    EXPECT_TRUE(chain.poseAt(f).X.isApprox(odo.pose[f], 1e-9)) << f;
    chain.forgetBefore(f);
  }
}
