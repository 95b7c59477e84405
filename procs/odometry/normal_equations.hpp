// The robust normal equations of one registration: for every point-to-line (LOAM eq. (2)) and
// point-to-plane (eq. (3)) correspondence at the motion x = [t; w] (rigid_motion.hpp), the
// Huber-weighted sums H = sum(rho' J^T J), g = sum(rho' J^T r) and the cost 1/2 sum(rho(r^2)),
// in one pass over the contiguous match arrays.
//
// Why hand-written: on the real KITTI slice Ceres' Levenberg-Marquardt over the same residuals
// took 32 % of the odometry's instructions (callgrind, 3.2 G of 10.1 G for 30 scans), most of
// it problem construction and per-block bookkeeping for a problem with 6 unknowns;
// `odometry_bench --benchmark_filter=PoseSolve` compares the two on real matches (docs/results.md).
// The residuals are the ones of edge_residual.hpp / plane_residual.hpp, which the Ceres
// reference solve (solvePoseCeres) still uses; tests check both against numeric differences.
#pragma once

#include "pose_solver.hpp"
#include "rigid_motion.hpp"

namespace dlslot::odometry {

struct NormalEquations {
  Matrix6d H = Matrix6d::Zero();   // sum(rho' J^T J)
  Vector6d g = Vector6d::Zero();   // sum(rho' J^T r)
  double cost = 0.0;               // 1/2 sum(rho(|r|^2)), Ceres' convention
  int num_inliers = 0;             // |r| <= huber delta (with inlier_statistics)
  double sum_abs_inliers = 0.0;    // sum |r| over the inliers (with inlier_statistics)
};

// Linearizes all matches at x (matches in the reference frame of the parameterization).
// inlier_statistics false: num_inliers and sum_abs_inliers are left at 0 (no square root per
// inlier; the solve's own steps need only H, g and the cost).
NormalEquations linearize(const Matches& matches, const double* x, double huber_delta, bool inlier_statistics = true);

// One residual and its 1x6 / 3x6 Jacobian at x, for tests.
double planeResidual(const PlaneMatch& m, const RigidMotion& motion, Eigen::Matrix<double, 1, 6>* J);
Eigen::Vector3d edgeResidual(const EdgeMatch& m, const RigidMotion& motion, Matrix36d* J);

}  // namespace dlslot::odometry
