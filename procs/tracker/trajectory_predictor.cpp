#include "trajectory_predictor.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
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

// The normal equations A^T A theta = A^T b of eq. 5 for x and y at once, in normalised time.
// Monomials nest, so the system of a lower degree is the top-left block of this one.
struct NormalEquations {
  double mid = 0, half = 1;
  Normal AtA;
  Rhs Atb;
  NormalEquations(const std::vector<TrajectoryPoint>& points, int degree) {
    const double t0 = points.front().time_s, t1 = points.back().time_s;
    mid = 0.5 * (t0 + t1);
    half = 0.5 * (t1 - t0);
    AtA = Normal::Zero(degree + 1, degree + 1);
    Atb = Rhs::Zero(degree + 1, 2);
    for (const TrajectoryPoint& p : points) {
      const Coeffs a = powers(normalised(p.time_s), degree);
      AtA.noalias() += a * a.transpose();
      Atb.noalias() += a * p.position.head<2>().transpose();
    }
  }
  double normalised(double t) const { return (t - mid) / half; }
};

}  // namespace

Prediction predictPolynomial(const std::vector<TrajectoryPoint>& points, double time_s, int max_degree,
                             double max_noise_gain) {
  if (points.empty()) throw std::invalid_argument("predictPolynomial: no points");
  Prediction out;
  double z = 0.0;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const TrajectoryPoint& p : points) {
    z += p.position.z();
    mean += p.position.head<2>();
  }
  const double n = static_cast<double>(points.size());
  out.position << mean / n, z / n;
  out.noise_gain = 1.0 / std::sqrt(n);
  // Observations at one instant carry no velocity: the best guess is where they are.
  if (points.size() < 2 || points.back().time_s <= points.front().time_s) return out;

  const int top = std::clamp(std::min(max_degree, static_cast<int>(points.size()) - 1), 1, kMaxCoeffs - 1);
  const NormalEquations eq(points, top);
  const Coeffs a_top = powers(eq.normalised(time_s), top);
  for (int degree = top; degree >= 1; --degree) {
    const int m = degree + 1;
    const Eigen::LDLT<Normal> ldlt(Normal(eq.AtA.topLeftCorner(m, m)));
    const Coeffs a = a_top.head(m);
    // Var(a^T theta) = sigma^2 a^T (A^T A)^-1 a for white observation noise.
    const double gain = std::sqrt(std::max(0.0, a.dot(ldlt.solve(a))));
    if (gain > max_noise_gain && degree > 1) continue;
    const Rhs theta = ldlt.solve(Rhs(eq.Atb.topRows(m)));
    out.position.head<2>() = (a.transpose() * theta).transpose();
    out.degree = degree;
    out.noise_gain = gain;
    return out;
  }
  return out;  // not reached: degree 1 always returns
}

double windowDisplacement(const std::vector<TrajectoryPoint>& points) {
  if (points.size() < 2 || points.back().time_s <= points.front().time_s) return 0.0;
  // Least-squares velocity (the slope of a line through the window) times the window's span.
  double t_mean = 0;
  Eigen::Vector2d p_mean = Eigen::Vector2d::Zero();
  for (const TrajectoryPoint& p : points) {
    t_mean += p.time_s;
    p_mean += p.position.head<2>();
  }
  t_mean /= static_cast<double>(points.size());
  p_mean /= static_cast<double>(points.size());
  double stt = 0;
  Eigen::Vector2d stp = Eigen::Vector2d::Zero();
  for (const TrajectoryPoint& p : points) {
    const double dt = p.time_s - t_mean;
    stt += dt * dt;
    stp += dt * (p.position.head<2>() - p_mean);
  }
  return (stp / stt).norm() * (points.back().time_s - points.front().time_s);
}

}  // namespace dlslot::tracker
