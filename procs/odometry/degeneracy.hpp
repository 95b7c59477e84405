// How well a registration constrains the translation, per direction (Zhang, Kaess and Singh, "On
// degeneracy of optimization-based state estimation problems", ICRA 2016: the eigen-decomposition
// of the normal equations). The rotation is marginalised out (the Schur complement of the
// rotation block of J^T J), so the numbers are the information each direction of translation has
// whatever the rotation: along a highway the guard rails and the road constrain the lateral and
// vertical position and the rotation well, the position along the road hardly at all.
//
// A direction is weak when its information is below `weak_ratio` times the strongest direction's
// (its standard deviation 1 / sqrt(weak_ratio) times the best one's): a ratio of the problem's own
// numbers, the same whatever the number of correspondences or the residual sigma.
#pragma once

#include <Eigen/Core>

#include "dlslot/convert.hpp"  // Matrix6d

namespace dlslot::odometry {

struct TranslationConstraint {
  Eigen::Vector3d information = Eigen::Vector3d::Zero();  // eigenvalues, ascending (1/m^2 * residual units)
  Eigen::Matrix3d directions = Eigen::Matrix3d::Identity();  // columns: unit eigenvectors, same order
  // information(0) / information(2): 1 for a perfectly even constraint, 0 for a direction with none.
  double ratio() const { return information(2) > 0 ? information(0) / information(2) : 0.0; }
  Eigen::Vector3d weakest() const { return directions.col(0); }
};

// From a normal matrix in tangent order (t, w) as PoseSolution::normal_matrix holds it; the
// directions are in the frame the translation is perturbed in (the current lidar frame).
TranslationConstraint translationConstraint(const Matrix6d& normal_matrix);

// Chi-square of the difference d between two independent estimates of one translation, along the
// unit direction v, with covariances Ca and Cb (3x3): (v.d)^2 / (v^T (Ca + Cb) v), chi-square
// with 1 degree of freedom when both are right.
double chiSquareAlong(const Eigen::Vector3d& d, const Eigen::Vector3d& v, const Eigen::Matrix3d& Ca,
                      const Eigen::Matrix3d& Cb);

}  // namespace dlslot::odometry
