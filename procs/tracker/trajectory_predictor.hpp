// Position prediction from a trajectory's window of observations (paper III-B, eq. 3-5):
// a polynomial p(t) = th1 t^3 + th2 t^2 + th3 t + th4 fitted per axis (x and y) by least
// squares over the window, evaluated at the new frame's time.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace dlslot::tracker {

// One observation of a trajectory: where (world frame) and when.
struct TrajectoryPoint {
  int frame = 0;
  double time_s = 0.0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
};

// The degree actually fitted to n observations: at most max_degree, and at least two
// observations per non-constant coefficient ((n - 1) / 2), so no fit interpolates its points
// exactly. An interpolating cubic through 4 noisy points extrapolates one step with 8.3x the
// position noise; the least-squares cubic through 10 points with 1.9x, a line through 3 points
// with 1.5x. Never below 1 for n >= 2 (a moving object needs at least a velocity).
int polynomialDegree(int num_points, int max_degree);

// Predicted world position at `time_s` (eq. 3-5). Time is centred and scaled to [-1, 1] over the
// window before fitting, so the normal equations stay well conditioned whatever the clock's
// origin. x and y come from the polynomials; z (not modelled by the paper) is the mean height.
// `points` must be non-empty and in time order.
Eigen::Vector3d predictPolynomial(const std::vector<TrajectoryPoint>& points, double time_s, int max_degree = 3);

// Net displacement over the window in the xy plane, from a least-squares line (so observation
// noise on a parked car does not read as motion): the basis of the static/dynamic guess (III-D).
double windowDisplacement(const std::vector<TrajectoryPoint>& points);

}  // namespace dlslot::tracker
