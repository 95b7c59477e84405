// The backend's consistency test of the odometry factor (eq. 8) against what the window's
// objects say about the same motion. A LiDAR odometry on a degenerate drive (a highway: rails
// and road alike along it, traffic moving with the ego) can keep a wrong velocity, and its
// covariance (the scan-to-map Hessian's) stays small: in eq. 12 it then outweighs every box by
// orders of magnitude and the joint estimate follows it, although its static landmarks move
// metres against it every frame.
//
// Per frame, before the solve: every object in the graph that was observed at t-1 and at t
// gives an estimate of the ego's translation from t-1 to t (in the lidar axes of t-1):
//   static landmark:  b_{t-1} = X_{t-1}^-1 L, b_t = X_t^-1 L          =>  t = p_{t-1} - R p_t
//   moving object:    its world position moves by v dt (its velocity before this frame, eq. 11)
//                     =>  t = p_{t-1} + R_{t-1}^T v dt - R p_t
// (p: box centres, R: the odometry's rotation, which is not in question: a box's yaw is a far
// worse rotation sensor than the scan-to-map registration). None of them uses this frame's
// odometry translation. Their largest mutually consistent subset (chi-square gate between
// pairs) is fused by information; with at least `min_support` objects in it, the odometry's
// translation d = t_objects - t_odometry is tested:
//   chi2 = d^T (Sigma_odometry + Sigma_objects)^-1 d  >  chi2_3(probability)  ->  disagreement.
// A disagreeing odometry factor gets its translation covariance multiplied by the factor k that
// brings chi2 down to its expected value, the 3 dof (d^T (k Sigma_odometry + Sigma_objects)^-1 d
// = 3): the disagreement then is an ordinary residual of the inflated covariance. Inflated only
// to the gate, it would still pull each frame's motion by gate sigma^2 / d toward the odometry
// (sigma^2 the objects' variance along d), 21/3 = 7 times more: 9 cm a frame on the unit test's
// highway, 2 cm at dof. The frame's ego pose starts from the objects' translation. A frame that
// passes is not touched at all: its factor, its start and so its solution are exactly what
// they were without the test.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace dlslot::backend {

// One object's estimate of the ego's translation from frame t-1 to t (lidar axes of t-1).
struct MotionEvidence {
  int track_id = -1;
  bool moving = false;
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();
};

struct ConsistencyOptions {
  bool enabled = true;
  // Probability of the chi-square gate (3 dof) for both the objects' consensus and the test.
  double probability = 0.9999;
  // Objects that must agree before they may overrule the odometry: one box pair can be a wrong
  // association; two independent objects agreeing by chance on the same wrong motion cannot.
  int min_support = 2;
  // false: test and report only, the odometry factor is never down-weighted.
  bool downweight = true;
};

enum class OdometryCheckOutcome : int {
  kUntested = 0,      // no odometry factor this frame, the test off, or too few objects agreeing
  kConsistent = 1,    // within the gate
  kDownweighted = 2,  // beyond it: the factor's translation covariance inflated
  kDisagreed = 3,     // beyond it, reported only (downweight: false)
};
const char* toString(OdometryCheckOutcome outcome);

struct OdometryCheck {
  OdometryCheckOutcome outcome = OdometryCheckOutcome::kUntested;
  int evidence = 0;  // objects that gave an estimate
  int support = 0;   // of them, in the consensus
  double gate = 0;   // chi-square quantile (3 dof)
  double chi2 = 0;   // of the odometry against the consensus (0 when untested)
  double disagreement_m = 0;  // |t_objects - t_odometry|
  double inflation = 1;       // factor on the odometry's translation covariance (1: untouched)
  double target_chi2 = 3;     // what the inflation brings chi2 to (its expected value, the dof)
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();  // the objects' consensus
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  bool disagreed() const {
    return outcome == OdometryCheckOutcome::kDownweighted || outcome == OdometryCheckOutcome::kDisagreed;
  }
  std::string text() const;  // one line for SLOT_STATE's status_text ("" when untested)
};

// The quantile of the chi-square distribution with `dof` degrees of freedom at probability p.
double chiSquareQuantile(double p, int dof);

// The test above: the odometry's translation and its covariance (lidar axes of t-1) against the
// objects' estimates.
OdometryCheck checkOdometry(const Eigen::Vector3d& odometry_translation, const Eigen::Matrix3d& odometry_covariance,
                            const std::vector<MotionEvidence>& evidence, const ConsistencyOptions& options);

}  // namespace dlslot::backend
