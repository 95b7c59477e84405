// LOAM's smoothness (LOAM eq. (1), unnormalised as in A-LOAM): for point i of a ring,
// c_i = || sum_{j=i-w..i+w, j!=i} (p_j - p_i) ||^2. Large on edges, small on planes.
#pragma once

#include <Eigen/Core>

namespace dlslot::odometry {

// Curvature of every point of one ring (points in firing order); the first and last
// `half_window` points have no full window and get -1.
Eigen::VectorXf ringCurvature(const Eigen::Ref<const Eigen::Matrix3Xf>& ring, int half_window);

}  // namespace dlslot::odometry
