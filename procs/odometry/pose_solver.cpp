#include "pose_solver.hpp"

#include <ceres/ceres.h>

#include <Eigen/Eigenvalues>

#include "edge_residual.hpp"
#include "plane_residual.hpp"

namespace dlslot::odometry {

Matches expressedIn(const Matches& m, const Pose& T_ref_new) {
  const Pose T_new_ref = T_ref_new.inverse();
  const Eigen::Matrix3d R = T_new_ref.linear();
  Matches out;
  out.edges.reserve(m.edges.size());
  out.planes.reserve(m.planes.size());
  for (const EdgeMatch& e : m.edges) out.edges.push_back({e.p, T_new_ref * e.a, R * e.u});
  // n . x + d = 0 with x = T_ref_new y  =>  (R^T n) . y + (n . t + d) = 0
  for (const PlaneMatch& p : m.planes)
    out.planes.push_back({p.p, R * p.n, p.n.dot(T_ref_new.translation()) + p.d});
  return out;
}

namespace {

// sum(rho' J^T J) and inlier residual statistics at x = 0 (matches expressed in the solution frame).
void measureConstraint(const Matches& m, const ceres::LossFunction& loss, double huber_delta, PoseSolution& s) {
  const double zero[6] = {0, 0, 0, 0, 0, 0};
  const double* params[1] = {zero};
  double sum_abs = 0.0;
  auto add = [&](const ceres::CostFunction& cost, int dim) {
    double r[3], jac[18];
    double* jacs[1] = {jac};
    cost.Evaluate(params, r, jacs);
    const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor>> J(jac, dim, 6);
    const double sq = Eigen::Map<const Eigen::VectorXd>(r, dim).squaredNorm();
    double rho[3];
    loss.Evaluate(sq, rho);
    s.normal_matrix += rho[1] * J.transpose() * J;
    if (sq <= huber_delta * huber_delta) {
      sum_abs += std::sqrt(sq);
      ++s.num_inliers;
    }
  };
  RigidMotion motion;
  for (const EdgeMatch& e : m.edges) add(EdgeResidual(e.p, e.a, e.u, motion), 3);
  for (const PlaneMatch& p : m.planes) add(PlaneResidual(p.p, p.n, p.d, motion), 1);
  s.residual_mean = s.num_inliers > 0 ? sum_abs / s.num_inliers : 0.0;
  s.min_eigenvalue = Eigen::SelfAdjointEigenSolver<Matrix6d>(s.normal_matrix, Eigen::EigenvaluesOnly).eigenvalues()[0];
}

}  // namespace

PoseSolution solvePose(const Matches& matches, const Pose& guess, const SolverConfig& cfg) {
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
  measureConstraint(expressedIn(matches, sol.T_ref_cur), loss, cfg.huber_delta_m, sol);
  return sol;
}

Registration registerIteratively(const std::function<Matches(const Pose&)>& match, const Pose& guess,
                                 const SolverConfig& cfg, int min_correspondences) {
  Registration r;
  r.solution.T_ref_cur = guess;
  for (int it = 0; it < cfg.outer_iterations; ++it) {
    const Matches m = match(r.solution.T_ref_cur);
    r.num_correspondences = static_cast<int>(m.size());
    if (r.num_correspondences < min_correspondences) {
      r.solution.ok = false;
      break;
    }
    const Pose before = r.solution.T_ref_cur;
    r.solution = solvePose(m, before, cfg);
    if (!r.solution.ok) break;
    // Correspondences searched at a pose this close to the solution would be the same ones.
    const Pose step = before.inverse() * r.solution.T_ref_cur;
    if (step.translation().norm() < cfg.converged_step_m &&
        Eigen::AngleAxisd(step.linear()).angle() < cfg.converged_step_deg * M_PI / 180.0)
      break;
  }
  return r;
}

}  // namespace dlslot::odometry
