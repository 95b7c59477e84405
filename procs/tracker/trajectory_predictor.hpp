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
  // The box sat inside the box of a track of another class at this frame (class plausibility,
  // trajectory_associator.hpp); the prediction does not use it.
  bool on_other_class = false;
};

struct Prediction {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  int degree = 0;          // degree of the polynomial used
  double noise_gain = 1.0; // predicted-position noise / observation noise (per axis, white noise)
};

// Predicted world position at `time_s` (eq. 3-5). `points` must be non-empty, in time order.
//
// Well conditioned in two senses. Numerically: time is centred and scaled to [-1, 1] over the
// window before fitting, whatever the clock's origin. Statistically: a least-squares polynomial
// extrapolates its observations' noise with a gain that grows with the degree and with the
// horizon (a cubic through 4 points predicts one frame ahead with 8.3x the noise, three frames
// ahead with 62x; through 10 points with 1.9x and 6x). So the degree is the highest one, up to
// max_degree, whose gain stays within max_noise_gain; a short history or a prediction across
// missed frames gets a lower degree, never below a line. z (not modelled by the paper) is the
// mean height.
Prediction predictPolynomial(const std::vector<TrajectoryPoint>& points, double time_s, int max_degree = 3,
                             double max_noise_gain = 3.0);

// Net displacement over the window in the xy plane, from a least-squares line (so observation
// noise on a parked car does not read as motion): the basis of the static/dynamic guess (III-D).
double windowDisplacement(const std::vector<TrajectoryPoint>& points);

}  // namespace dlslot::tracker
