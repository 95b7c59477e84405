#include "trajectory_predictor.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <stdexcept>

namespace dlslot::tracker {
namespace {

constexpr int kMaxCoeffs = 4;  // cubic
using Normal = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, kMaxCoeffs, kMaxCoeffs>;
using Rhs = Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::ColMajor, kMaxCoeffs, 2>;
using Coeffs = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, kMaxCoeffs, 1>;

// Monomials 1, s, s^2, ... up to `degree`.
Coeffs powers(double s, int degree) {
  Coeffs p(degree + 1);
  p(0) = 1.0;
  for (int k = 1; k <= degree; ++k) p(k) = p(k - 1) * s;
  return p;
}

// Least-squares polynomial of `degree` through the xy of `points`, evaluated at time_s (eq. 5).
Eigen::Vector2d fitAndEvaluate(const std::vector<TrajectoryPoint>& points, double time_s, int degree) {
  const double t0 = points.front().time_s, t1 = points.back().time_s;
  const double mid = 0.5 * (t0 + t1), half = 0.5 * (t1 - t0);
  Normal AtA = Normal::Zero(degree + 1, degree + 1);
  Rhs Atb = Rhs::Zero(degree + 1, 2);
  for (const TrajectoryPoint& p : points) {
    const Coeffs a = powers((p.time_s - mid) / half, degree);
    AtA.noalias() += a * a.transpose();
    Atb.noalias() += a * p.position.head<2>().transpose();
  }
  const Rhs theta = AtA.ldlt().solve(Atb);
  return (powers((time_s - mid) / half, degree).transpose() * theta).transpose();
}

}  // namespace

int polynomialDegree(int num_points, int max_degree) {
  if (num_points < 2) return 0;
  return std::clamp((num_points - 1) / 2, 1, std::clamp(max_degree, 1, kMaxCoeffs - 1));
}

Eigen::Vector3d predictPolynomial(const std::vector<TrajectoryPoint>& points, double time_s, int max_degree) {
  if (points.empty()) throw std::invalid_argument("predictPolynomial: no points");
  double z = 0.0;
  for (const TrajectoryPoint& p : points) z += p.position.z();
  z /= static_cast<double>(points.size());

  // Observations at one instant carry no velocity: the best guess is where they are.
  const int degree = polynomialDegree(static_cast<int>(points.size()), max_degree);
  if (degree == 0 || points.back().time_s <= points.front().time_s) {
    Eigen::Vector2d xy = Eigen::Vector2d::Zero();
    for (const TrajectoryPoint& p : points) xy += p.position.head<2>();
    xy /= static_cast<double>(points.size());
    return {xy.x(), xy.y(), z};
  }
  const Eigen::Vector2d xy = fitAndEvaluate(points, time_s, degree);
  return {xy.x(), xy.y(), z};
}

double windowDisplacement(const std::vector<TrajectoryPoint>& points) {
  if (points.size() < 2 || points.back().time_s <= points.front().time_s) return 0.0;
  const Eigen::Vector2d first = fitAndEvaluate(points, points.front().time_s, 1);
  const Eigen::Vector2d last = fitAndEvaluate(points, points.back().time_s, 1);
  return (last - first).norm();
}

}  // namespace dlslot::tracker
