// The registration residuals (LOAM eq. (2), (3); A-LOAM's edge and plane factors): values at
// known poses, Jacobians against numeric differentiation, and the pose solve on exact matches.
#include <gtest/gtest.h>

#include <random>

#include "odometry/edge_residual.hpp"
#include "odometry/plane_residual.hpp"
#include "odometry/pose_solver.hpp"
#include "odometry/rigid_motion.hpp"

namespace dlslot::odometry {
namespace {

// Central differences of cost at x, compared with its analytic Jacobian.
void expectJacobianMatchesNumeric(const ceres::CostFunction& cost, const double* x) {
  const int m = cost.num_residuals();
  std::vector<double> r(m), J(m * 6);
  double* jacs[1] = {J.data()};
  const double* params[1] = {x};
  ASSERT_TRUE(cost.Evaluate(params, r.data(), jacs));
  const double h = 1e-6;
  for (int j = 0; j < 6; ++j) {
    double xp[6], xm[6];
    std::copy(x, x + 6, xp);
    std::copy(x, x + 6, xm);
    xp[j] += h;
    xm[j] -= h;
    std::vector<double> rp(m), rm(m);
    const double* pp[1] = {xp};
    const double* pm[1] = {xm};
    cost.Evaluate(pp, rp.data(), nullptr);
    cost.Evaluate(pm, rm.data(), nullptr);
    for (int i = 0; i < m; ++i) EXPECT_NEAR(J[i * 6 + j], (rp[i] - rm[i]) / (2 * h), 1e-6) << "d r" << i << " / d x" << j;
  }
}

TEST(OdometryResidual, EdgeIsThePerpendicularOffsetFromTheLine) {
  RigidMotion motion;
  const Eigen::Vector3d a(1, 2, 3), u = Eigen::Vector3d(1, 1, 0).normalized();
  const Eigen::Vector3d off = Eigen::Vector3d(0, 0, 0.3) + 0.2 * Eigen::Vector3d(1, -1, 0).normalized();
  const EdgeResidual cost(a + 4.0 * u + off, a, u, motion);  // 4 m along the line, then off it
  const double x[6] = {0, 0, 0, 0, 0, 0};
  const double* params[1] = {x};
  double r[3];
  ASSERT_TRUE(cost.Evaluate(params, r, nullptr));
  EXPECT_NEAR(r[0], off.x(), 1e-12);
  EXPECT_NEAR(r[1], off.y(), 1e-12);
  EXPECT_NEAR(r[2], off.z(), 1e-12);

  // A translation along the line does not change it; one across it does.
  const double along[6] = {u.x() * 2, u.y() * 2, 0, 0, 0, 0};
  const double* pa[1] = {along};
  ASSERT_TRUE(cost.Evaluate(pa, r, nullptr));
  EXPECT_NEAR(Eigen::Map<Eigen::Vector3d>(r).norm(), off.norm(), 1e-12);
  const double up[6] = {0, 0, -0.3, 0, 0, 0};
  const double* pu[1] = {up};
  ASSERT_TRUE(cost.Evaluate(pu, r, nullptr));
  EXPECT_NEAR(Eigen::Map<Eigen::Vector3d>(r).norm(), 0.2, 1e-12);
}

TEST(OdometryResidual, PlaneIsTheSignedDistance) {
  RigidMotion motion;
  const Eigen::Vector3d n = Eigen::Vector3d(0, 0.6, 0.8);
  const PlaneResidual cost(Eigen::Vector3d(5, 0, 1), n, -2.0, motion);  // plane 0.6 y + 0.8 z = 2
  double r;
  const double x0[6] = {0, 0, 0, 0, 0, 0};
  const double* p0[1] = {x0};
  ASSERT_TRUE(cost.Evaluate(p0, &r, nullptr));
  EXPECT_NEAR(r, 0.8 - 2.0, 1e-12);
  // Rotating the point (5, 0, 1) by 90 deg about z gives (0, 5, 1): 0.6 * 5 + 0.8 - 2 = 1.8.
  const double x1[6] = {0, 0, 0, 0, 0, M_PI / 2};
  const double* p1[1] = {x1};
  ASSERT_TRUE(cost.Evaluate(p1, &r, nullptr));
  EXPECT_NEAR(r, 1.8, 1e-12);
}

TEST(OdometryResidual, JacobiansMatchNumericDifferentiation) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    RigidMotion motion;
    const Eigen::Vector3d p(20 * U(rng), 20 * U(rng), 3 * U(rng));
    const Eigen::Vector3d a(20 * U(rng), 20 * U(rng), 3 * U(rng));
    const Eigen::Vector3d dir = Eigen::Vector3d(U(rng), U(rng), U(rng)).normalized();
    // Rotations up to ~0.9 rad: the left Jacobian of SO(3) matters, not just small angles.
    const double x[6] = {2 * U(rng), 2 * U(rng), 2 * U(rng), 0.5 * U(rng), 0.5 * U(rng), 0.5 * U(rng)};
    expectJacobianMatchesNumeric(EdgeResidual(p, a, dir, motion), x);
    expectJacobianMatchesNumeric(PlaneResidual(p, dir, 3 * U(rng), motion), x);
  }
}

TEST(OdometryResidual, SharedMotionFollowsTheParameters) {
  RigidMotion motion;
  const Eigen::Vector3d p(1, 2, 3);
  const double x1[6] = {1, 0, 0, 0, 0, 0}, x2[6] = {0, 0, 0, 0, 0, M_PI};
  EXPECT_TRUE(motion.at(x1).apply(p, nullptr).isApprox(Eigen::Vector3d(2, 2, 3)));
  EXPECT_TRUE(motion.at(x2).apply(p, nullptr).isApprox(Eigen::Vector3d(-1, -2, 3)));
  EXPECT_TRUE(motion.at(x1).apply(p, nullptr).isApprox(Eigen::Vector3d(2, 2, 3)));
}

TEST(OdometryResidual, LeftJacobianOfSO3) {
  const Eigen::Vector3d w(0.3, -0.5, 0.8), dw(1e-6, -2e-6, 1.5e-6);
  const Eigen::Matrix3d lhs = expSO3(w + dw);
  const Eigen::Matrix3d rhs = expSO3(leftJacobianSO3(w) * dw) * expSO3(w);
  EXPECT_LT((lhs - rhs).norm(), 1e-11);
  EXPECT_TRUE(leftJacobianSO3(Eigen::Vector3d::Zero()).isIdentity());
}

Pose knownMotion() {
  Pose T = Pose::Identity();
  T.linear() = expSO3(Eigen::Vector3d(0.02, -0.03, 0.15));
  T.translation() = Eigen::Vector3d(1.2, -0.4, 0.1);
  return T;
}

// Exact correspondences (lines and planes of every orientation) generated from T_ref_cur.
Matches exactMatches(const Pose& T_ref_cur) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  Matches m;
  for (int i = 0; i < 60; ++i) {
    const Eigen::Vector3d p(15 * U(rng), 15 * U(rng), 2 * U(rng));
    const Eigen::Vector3d q = T_ref_cur * p;
    const Eigen::Vector3d dir = Eigen::Vector3d(U(rng), U(rng), U(rng)).normalized();
    m.planes.push_back({p, dir, -dir.dot(q)});
    m.edges.push_back({p, q + 3.0 * U(rng) * dir, dir});
  }
  return m;
}

TEST(OdometryPoseSolver, RecoversAKnownMotionFromExactMatches) {
  const Pose truth = knownMotion();
  SolverConfig cfg;
  cfg.solver_iterations = 20;
  const PoseSolution s = solvePose(exactMatches(truth), Pose::Identity(), cfg);
  ASSERT_TRUE(s.ok);
  EXPECT_LT((s.T_ref_cur.translation() - truth.translation()).norm(), 1e-6);
  EXPECT_LT(Eigen::AngleAxisd(s.T_ref_cur.linear().transpose() * truth.linear()).angle(), 1e-6);
  EXPECT_NEAR(s.residual_mean, 0.0, 1e-6);
  EXPECT_EQ(s.num_inliers, 120);
  EXPECT_GT(s.min_eigenvalue, 1.0);
}

TEST(OdometryPoseSolver, ExpressedInKeepsResidualsUnchanged) {
  const Pose truth = knownMotion();
  const Matches m = exactMatches(truth);
  Pose frame = Pose::Identity();
  frame.linear() = expSO3(Eigen::Vector3d(0.1, 0.2, -0.3));
  frame.translation() = Eigen::Vector3d(3, -2, 1);
  const Matches local = expressedIn(m, frame);
  // In the new frame the solution is frame^-1 * truth: the residuals there are zero again.
  const Pose T = frame.inverse() * truth;
  for (const PlaneMatch& p : local.planes) EXPECT_NEAR(p.n.dot(T * p.p) + p.d, 0.0, 1e-9);
  for (const EdgeMatch& e : local.edges) EXPECT_NEAR(((T * e.p - e.a).cross(e.u)).norm(), 0.0, 1e-9);
}

TEST(OdometryPoseSolver, ParallelPlanesLeaveADegenerateDirection) {
  Matches m;
  for (int i = 0; i < 50; ++i) {  // the ground only: x, y and yaw unconstrained
    const Eigen::Vector3d p(i * 0.7 - 15, (i % 7) * 2.0 - 6, -1.7);
    m.planes.push_back({p, Eigen::Vector3d::UnitZ(), 1.7});
  }
  const PoseSolution s = solvePose(m, Pose::Identity(), SolverConfig());
  ASSERT_TRUE(s.ok);
  EXPECT_LT(s.min_eigenvalue, 1e-9);
  EXPECT_GT(s.normal_matrix(2, 2), 10.0);  // z is constrained
}

TEST(OdometryPoseSolver, NoMatchesIsNotASolution) {
  EXPECT_FALSE(solvePose(Matches(), Pose::Identity(), SolverConfig()).ok);
}

}  // namespace
}  // namespace dlslot::odometry
