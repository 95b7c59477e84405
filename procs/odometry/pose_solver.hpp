// One registration solve shared by scan-to-scan and scan-to-map: point-to-line and
// point-to-plane correspondences, Levenberg-Marquardt with a Huber loss on the 6x6 normal
// equations (normal_equations.hpp; Ceres' solve of the same problem is kept as the reference),
// and how well the result is constrained (the normal matrix J^T J at the solution and its
// smallest eigenvalue).
#pragma once

#include <Eigen/Core>
#include <functional>
#include <vector>

#include "dlslot/convert.hpp"  // Matrix6d
#include "dlslot/types.hpp"
#include "odometry_config.hpp"

namespace dlslot::odometry {

struct EdgeMatch {
  Eigen::Vector3d p;  // current frame
  Eigen::Vector3d a;  // a point of the line, reference frame
  Eigen::Vector3d u;  // unit direction of the line, reference frame
};

struct PlaneMatch {
  Eigen::Vector3d p;  // current frame
  Eigen::Vector3d n;  // unit normal, reference frame
  double d = 0.0;     // plane: n . x + d = 0
};

struct Matches {
  std::vector<EdgeMatch> edges;
  std::vector<PlaneMatch> planes;
  size_t size() const { return edges.size() + planes.size(); }
};

struct PoseSolution {
  Pose T_ref_cur = Pose::Identity();
  bool ok = false;               // the solve returned a usable, finite solution
  // Robust-weighted normal matrix sum(rho' J^T J) at the solution, for a right perturbation
  // T_ref_cur * (Exp(w), t) in tangent order (t, w); its smallest eigenvalue says how well the
  // worst-constrained direction is determined (near 0: degenerate, e.g. a corridor).
  Matrix6d normal_matrix = Matrix6d::Zero();
  double min_eigenvalue = 0.0;
  double residual_mean = 0.0;    // mean |r| (m) of the inliers (|r| <= huber delta)
  int num_inliers = 0;
};

// Solves for T_ref_cur from `guess`; matches are in the reference frame.
PoseSolution solvePose(const Matches& matches, const Pose& guess, const SolverConfig& cfg);
// The same solve by Ceres (pose_solver_ceres.cpp): the reference for tests and the benchmark.
PoseSolution solvePoseCeres(const Matches& matches, const Pose& guess, const SolverConfig& cfg);
// Fills s.normal_matrix, min_eigenvalue, residual_mean and num_inliers at s.T_ref_cur.
void measureConstraint(const Matches& matches, double huber_delta, PoseSolution& s);

struct Registration {
  PoseSolution solution;
  int num_correspondences = 0;  // of the last correspondence search
  // The last solve moved the pose less than converged_step_*: a further search would change
  // nothing. False after outer_iterations searches that each still moved it: the start was far
  // from the solution and the registration only went part of the way.
  bool converged = false;
  double last_step_m = 0.0;  // the translation of the last solve's step
  double match_ms = 0.0;        // CPU time of this thread in correspondence searches
  double solve_ms = 0.0;        // ...and in solves
};

// The outer loop of A-LOAM's odometry and mapping: up to cfg.outer_iterations times, search
// correspondences at the current estimate (`match`) and solve; stops early once a solve moves
// the estimate less than cfg.converged_step_*. Fails (solution.ok false) when a
// search finds fewer than min_correspondences or a solve fails.
Registration registerIteratively(const std::function<Matches(const Pose&)>& match, const Pose& guess,
                                 const SolverConfig& cfg, int min_correspondences);

// The same correspondences seen from a frame T_ref_new: what a solve starting there needs.
Matches expressedIn(const Matches& matches, const Pose& T_ref_new);

}  // namespace dlslot::odometry
