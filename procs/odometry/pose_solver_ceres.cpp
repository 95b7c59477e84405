// The Ceres reference for solvePose: the same residuals (edge_residual.hpp, plane_residual.hpp)
// and Huber loss, solved by Ceres' Levenberg-Marquardt. The odometry uses the hand-written
// solve (normal_equations.hpp says why); this one stays for the benchmark that justifies it and
// for the test that both give the same pose.
#include <ceres/ceres.h>

#include "edge_residual.hpp"
#include "plane_residual.hpp"
#include "pose_solver.hpp"

namespace dlslot::odometry {

PoseSolution solvePoseCeres(const Matches& matches, const Pose& guess, const SolverConfig& cfg) {
  PoseSolution sol;
  sol.T_ref_cur = guess;
  if (matches.size() == 0) return sol;

  // Parameters are the correction x to the guess (T_ref_cur = guess * T(x)), starting at zero.
  const Matches local = expressedIn(matches, guess);
  double x[6] = {0, 0, 0, 0, 0, 0};
  ceres::HuberLoss loss(cfg.huber_delta_m);
  RigidMotion motion;  // outlives the problem's residuals, which refer to it
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.enable_fast_removal = false;
  ceres::Problem problem(problem_options);
  for (const EdgeMatch& e : local.edges) problem.AddResidualBlock(new EdgeResidual(e.p, e.a, e.u, motion), &loss, x);
  for (const PlaneMatch& p : local.planes)
    problem.AddResidualBlock(new PlaneResidual(p.p, p.n, p.d, motion), &loss, x);

  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;  // 6 unknowns: the normal matrix is tiny
  options.max_num_iterations = cfg.solver_iterations;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  if (!summary.IsSolutionUsable() || !Eigen::Map<const Vector6d>(x).allFinite()) return sol;

  sol.T_ref_cur = orthonormalized(guess * poseFromParams(x));
  sol.ok = true;
  measureConstraint(matches, cfg.huber_delta_m, sol);
  return sol;
}

}  // namespace dlslot::odometry
