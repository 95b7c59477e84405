// The hand-written registration solve (normal_equations.hpp): residual Jacobians against
// numeric differentiation, the normal equations against a sum over the Ceres cost functions,
// and the Levenberg-Marquardt solve against Ceres' on noisy matches with outliers.
#include <gtest/gtest.h>

#include <ceres/loss_function.h>

#include <random>

#include "odometry/edge_residual.hpp"
#include "odometry/normal_equations.hpp"
#include "odometry/plane_residual.hpp"
#include "odometry/pose_solver.hpp"

namespace dlslot::odometry {
namespace {

Pose knownMotion() {
  Pose T = Pose::Identity();
  T.linear() = expSO3(Eigen::Vector3d(0.01, -0.02, 0.08));
  T.translation() = Eigen::Vector3d(0.9, -0.3, 0.05);
  return T;
}

// Correspondences of every orientation from T_ref_cur, with range noise and a share of
// outliers (points matched to the wrong surface), as a real search returns them.
Matches noisyMatches(const Pose& T_ref_cur, double noise_m, double outlier_share, unsigned seed = 5) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  std::normal_distribution<double> N(0.0, noise_m);
  Matches m;
  for (int i = 0; i < 300; ++i) {
    const Eigen::Vector3d p(20 * U(rng), 20 * U(rng), 2 * U(rng));
    Eigen::Vector3d q = T_ref_cur * p + Eigen::Vector3d(N(rng), N(rng), N(rng));
    if (std::abs(U(rng)) < outlier_share) q += Eigen::Vector3d(U(rng), U(rng), U(rng));
    const Eigen::Vector3d dir = Eigen::Vector3d(U(rng), U(rng), U(rng)).normalized();
    m.planes.push_back({p, dir, -dir.dot(q)});
    m.edges.push_back({p, q + 3.0 * U(rng) * dir, dir});
  }
  return m;
}

TEST(OdometryNormalEquations, JacobiansMatchNumericDifferentiation) {
  const Matches m = noisyMatches(knownMotion(), 0.05, 0.0);
  const double x[6] = {0.3, -0.2, 0.1, 0.05, -0.08, 0.2};
  const double h = 1e-6;
  RigidMotion motion, moved;
  motion.at(x);
  for (int k = 0; k < 10; ++k) {
    Matrix36d Je;
    Eigen::Matrix<double, 1, 6> Jp;
    edgeResidual(m.edges[k], motion, &Je);
    planeResidual(m.planes[k], motion, &Jp);
    for (int j = 0; j < 6; ++j) {
      double xp[6], xm[6];
      std::copy(x, x + 6, xp);
      std::copy(x, x + 6, xm);
      xp[j] += h;
      xm[j] -= h;
      const Eigen::Vector3d ep = edgeResidual(m.edges[k], moved.at(xp), nullptr);
      const double pp = planeResidual(m.planes[k], moved.at(xp), nullptr);
      const Eigen::Vector3d em = edgeResidual(m.edges[k], moved.at(xm), nullptr);
      const double pm = planeResidual(m.planes[k], moved.at(xm), nullptr);
      EXPECT_LT((Je.col(j) - (ep - em) / (2 * h)).norm(), 1e-6) << "edge " << k << " d/dx" << j;
      EXPECT_NEAR(Jp(j), (pp - pm) / (2 * h), 1e-6) << "plane " << k << " d/dx" << j;
    }
  }
}

TEST(OdometryNormalEquations, EqualTheSumOverTheCeresResiduals) {
  const Matches m = noisyMatches(knownMotion(), 0.05, 0.2);
  const double x[6] = {0.8, -0.25, 0.03, 0.01, -0.015, 0.07};
  const double delta = 0.1;
  const NormalEquations ne = linearize(m, x, delta);

  // The same sums from Ceres' cost functions and loss.
  ceres::HuberLoss loss(delta);
  RigidMotion motion;
  Matrix6d H = Matrix6d::Zero();
  Vector6d g = Vector6d::Zero();
  double cost = 0.0;
  const double* params[1] = {x};
  auto add = [&](const ceres::CostFunction& c, int dim) {
    double r[3], jac[18];
    double* jacs[1] = {jac};
    ASSERT_TRUE(c.Evaluate(params, r, jacs));
    const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor>> J(jac, dim, 6);
    const Eigen::Map<const Eigen::VectorXd> rv(r, dim);
    double rho[3];
    loss.Evaluate(rv.squaredNorm(), rho);
    H += rho[1] * J.transpose() * J;
    g += rho[1] * J.transpose() * rv;
    cost += 0.5 * rho[0];
  };
  for (const EdgeMatch& e : m.edges) add(EdgeResidual(e.p, e.a, e.u, motion), 3);
  for (const PlaneMatch& p : m.planes) add(PlaneResidual(p.p, p.n, p.d, motion), 1);
  EXPECT_LT((ne.H - H).norm(), 1e-9 * H.norm());
  EXPECT_LT((ne.g - g).norm(), 1e-9 * g.norm());
  EXPECT_NEAR(ne.cost, cost, 1e-9 * cost);
  EXPECT_GT(ne.num_inliers, 0);
  EXPECT_LT(ne.num_inliers, 600);  // the outliers are outside the Huber delta
}

TEST(OdometryNormalEquations, SolveAgreesWithCeres) {
  const Pose truth = knownMotion();
  const Matches m = noisyMatches(truth, 0.03, 0.15);
  SolverConfig cfg;  // the odometry's 4 iterations, Huber 0.1 m
  const Pose guess = Pose::Identity();
  const PoseSolution ours = solvePose(m, guess, cfg);
  const PoseSolution ceres = solvePoseCeres(m, guess, cfg);
  ASSERT_TRUE(ours.ok);
  ASSERT_TRUE(ceres.ok);
  // Both converge to the same robust optimum, near the truth.
  EXPECT_LT((ours.T_ref_cur.translation() - ceres.T_ref_cur.translation()).norm(), 2e-3);
  EXPECT_LT(Eigen::AngleAxisd(ours.T_ref_cur.linear().transpose() * ceres.T_ref_cur.linear()).angle(), 1e-4);
  EXPECT_LT((ours.T_ref_cur.translation() - truth.translation()).norm(), 0.02);
  EXPECT_NEAR(ours.residual_mean, ceres.residual_mean, 1e-3);
  EXPECT_NEAR(ours.num_inliers, ceres.num_inliers, 6);
}

TEST(OdometryNormalEquations, BadStepsAreRejected) {
  // From far away with one iteration the cost may only go down: never a worse pose than the guess.
  const Pose truth = knownMotion();
  const Matches m = noisyMatches(truth, 0.0, 0.0);
  SolverConfig cfg;
  cfg.solver_iterations = 1;
  const double zero[6] = {0, 0, 0, 0, 0, 0};
  const PoseSolution s = solvePose(m, Pose::Identity(), cfg);
  ASSERT_TRUE(s.ok);
  const NormalEquations before = linearize(m, zero, cfg.huber_delta_m);
  const NormalEquations after = linearize(expressedIn(m, s.T_ref_cur), zero, cfg.huber_delta_m);
  EXPECT_LE(after.cost, before.cost);
}

}  // namespace
}  // namespace dlslot::odometry
