#include "pose_solver.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <cmath>

#include "dlslot/cpu_clock.hpp"
#include "normal_equations.hpp"

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

// The robust normal matrix and inlier statistics of the correspondences at the solution
// (matches re-expressed in the solution frame, x = 0).
void measureConstraint(const Matches& matches, double huber_delta, PoseSolution& s) {
  const double zero[6] = {0, 0, 0, 0, 0, 0};
  const NormalEquations ne = linearize(expressedIn(matches, s.T_ref_cur), zero, huber_delta);
  s.normal_matrix = ne.H;
  s.num_inliers = ne.num_inliers;
  s.residual_mean = ne.num_inliers > 0 ? ne.sum_abs_inliers / ne.num_inliers : 0.0;
  s.min_eigenvalue = Eigen::SelfAdjointEigenSolver<Matrix6d>(s.normal_matrix, Eigen::EigenvaluesOnly).eigenvalues()[0];
}

PoseSolution solvePose(const Matches& matches, const Pose& guess, const SolverConfig& cfg) {
  PoseSolution sol;
  sol.T_ref_cur = guess;
  if (matches.size() == 0) return sol;

  // Levenberg-Marquardt on the 6x6 normal equations, as Ceres runs it for this problem: the
  // correction x to the guess (T_ref_cur = guess * T(x)) starts at zero, a step solves
  // (H + lambda diag(H)) dx = -g, and is kept only when it lowers the robust cost; lambda
  // starts at Ceres' 1 / initial trust region radius (1e-4), shrinks after a kept step and grows
  // after a rejected one. Every try counts as one of cfg.solver_iterations.
  const Matches local = expressedIn(matches, guess);
  Vector6d x = Vector6d::Zero();
  NormalEquations ne = linearize(local, x.data(), cfg.huber_delta_m, false);
  if (!std::isfinite(ne.cost)) return sol;
  double lambda = 1e-4;
  for (int it = 0; it < cfg.solver_iterations; ++it) {
    Matrix6d A = ne.H;
    A.diagonal() += lambda * ne.H.diagonal().cwiseMax(1e-6);
    const Vector6d dx = A.ldlt().solve(-ne.g);
    if (!dx.allFinite()) break;
    const Vector6d x_new = x + dx;
    NormalEquations next = linearize(local, x_new.data(), cfg.huber_delta_m, false);
    if (std::isfinite(next.cost) && next.cost < ne.cost) {
      const double decrease = (ne.cost - next.cost) / std::max(ne.cost, 1e-300);
      x = x_new;
      ne = std::move(next);
      lambda = std::max(lambda / 3.0, 1e-12);
      // Ceres' function and parameter tolerances: further steps would change nothing.
      if (decrease < 1e-6 || dx.norm() <= 1e-8 * (x.norm() + 1e-8)) break;
    } else {
      lambda *= 4.0;
    }
  }
  if (!x.allFinite()) return sol;

  sol.T_ref_cur = orthonormalized(guess * poseFromParams(x.data()));
  sol.ok = true;
  measureConstraint(matches, cfg.huber_delta_m, sol);
  return sol;
}

Registration registerIteratively(const std::function<Matches(const Pose&)>& match, const Pose& guess,
                                 const SolverConfig& cfg, int min_correspondences) {
  Registration r;
  r.solution.T_ref_cur = guess;
  for (int it = 0; it < cfg.outer_iterations; ++it) {
    double t = threadCpuMs();
    const Matches m = match(r.solution.T_ref_cur);
    r.match_ms += threadCpuMs() - t;
    r.num_correspondences = static_cast<int>(m.size());
    if (r.num_correspondences < min_correspondences) {
      r.solution.ok = false;
      break;
    }
    const Pose before = r.solution.T_ref_cur;
    t = threadCpuMs();
    r.solution = solvePose(m, before, cfg);
    r.solve_ms += threadCpuMs() - t;
    if (!r.solution.ok) break;
    // Correspondences searched at a pose this close to the solution would be the same ones.
    const Pose step = before.inverse() * r.solution.T_ref_cur;
    r.last_step_m = step.translation().norm();
    if (step.translation().norm() < cfg.converged_step_m &&
        Eigen::AngleAxisd(step.linear()).angle() < cfg.converged_step_deg * M_PI / 180.0) {
      r.converged = true;
      break;
    }
  }
  return r;
}

}  // namespace dlslot::odometry
