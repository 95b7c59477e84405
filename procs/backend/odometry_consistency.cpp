#include "backend/odometry_consistency.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace dlslot::backend {
namespace {

// d^T C^-1 d; infinity when C is not positive definite.
double mahalanobis2(const Eigen::Vector3d& d, const Eigen::Matrix3d& C) {
  const Eigen::LLT<Eigen::Matrix3d> llt(C);
  if (llt.info() != Eigen::Success) return std::numeric_limits<double>::infinity();
  return d.dot(llt.solve(d));
}

// The regularized lower incomplete gamma function P(a, x) by its series (x small enough for
// the quantiles asked here: a few tens).
double lowerGammaP(double a, double x) {
  if (x <= 0) return 0.0;
  double term = 1.0 / a, sum = term;
  for (int n = 1; n < 1000 && std::abs(term) > 1e-16 * std::abs(sum); ++n) {
    term *= x / (a + n);
    sum += term;
  }
  return std::min(1.0, sum * std::exp(-x + a * std::log(x) - std::lgamma(a)));
}

}  // namespace

const char* toString(OdometryCheckOutcome outcome) {
  switch (outcome) {
    case OdometryCheckOutcome::kUntested: return "untested";
    case OdometryCheckOutcome::kConsistent: return "consistent";
    case OdometryCheckOutcome::kDownweighted: return "down-weighted";
    case OdometryCheckOutcome::kDisagreed: return "disagreed";
  }
  return "?";
}

std::string OdometryCheck::text() const {
  if (outcome == OdometryCheckOutcome::kUntested) return "";
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "odometry %s: %.3f m from the motion %d of %d objects agree on (chi-square %.1f, gate %.2f)",
                toString(outcome), disagreement_m, support, evidence, chi2, gate);
  std::string s = buf;
  if (outcome == OdometryCheckOutcome::kDownweighted) {
    std::snprintf(buf, sizeof buf, "; translation covariance x%.3g", inflation);
    s += buf;
  }
  return s;
}

double chiSquareQuantile(double p, int dof) {
  if (!(p > 0 && p < 1) || dof < 1) throw std::invalid_argument("chiSquareQuantile: expected 0 < p < 1 and dof >= 1");
  const double a = 0.5 * dof;
  double lo = 0, hi = 1;
  while (lowerGammaP(a, 0.5 * hi) < p) hi *= 2;
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo + hi);
    (lowerGammaP(a, 0.5 * mid) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

OdometryCheck checkOdometry(const Eigen::Vector3d& odometry_translation, const Eigen::Matrix3d& odometry_covariance,
                            const std::vector<MotionEvidence>& evidence, const ConsistencyOptions& options) {
  OdometryCheck check;
  check.evidence = static_cast<int>(evidence.size());
  check.gate = chiSquareQuantile(options.probability, 3);
  if (!options.enabled || check.evidence < options.min_support) return check;

  // The largest set of objects consistent with one of them (each pair's difference within the
  // gate of their summed covariances); ties go to the tighter set.
  const int n = check.evidence;
  std::vector<int> best;
  double best_sum = std::numeric_limits<double>::infinity();
  for (int i = 0; i < n; ++i) {
    std::vector<int> members;
    double sum = 0;
    for (int j = 0; j < n; ++j) {
      const double c2 = i == j ? 0.0
                               : mahalanobis2(evidence[j].translation - evidence[i].translation,
                                              evidence[i].covariance + evidence[j].covariance);
      if (c2 > check.gate) continue;
      members.push_back(j);
      sum += c2;
    }
    if (members.size() > best.size() || (members.size() == best.size() && sum < best_sum)) {
      best = std::move(members);
      best_sum = sum;
    }
  }
  check.support = static_cast<int>(best.size());
  if (check.support < options.min_support) return check;

  // Information-weighted mean of the consensus.
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
  Eigen::Vector3d weighted = Eigen::Vector3d::Zero();
  for (int j : best) {
    const Eigen::Matrix3d W = evidence[j].covariance.inverse();
    information += W;
    weighted += W * evidence[j].translation;
  }
  check.covariance = information.inverse();
  check.translation = check.covariance * weighted;

  const Eigen::Vector3d d = check.translation - odometry_translation;
  check.disagreement_m = d.norm();
  check.chi2 = mahalanobis2(d, odometry_covariance + check.covariance);
  if (check.chi2 <= check.gate) {
    check.outcome = OdometryCheckOutcome::kConsistent;
    return check;
  }
  if (!options.downweight) {
    check.outcome = OdometryCheckOutcome::kDisagreed;
    return check;
  }
  // The smallest k with d^T (k Sigma_odometry + Sigma_objects)^-1 d <= dof (decreasing in k),
  // by bisection on log k. The objects' own chi2 d^T Sigma_objects^-1 d is above the gate, so it
  // is reached at a finite k.
  const auto chi2At = [&](double k) { return mahalanobis2(d, k * odometry_covariance + check.covariance); };
  double lo = 1, hi = 2;
  while (chi2At(hi) > check.target_chi2 && hi < 1e30) {
    lo = hi;
    hi *= 16;
  }
  for (int i = 0; i < 60; ++i) {
    const double mid = std::sqrt(lo * hi);
    (chi2At(mid) > check.target_chi2 ? lo : hi) = mid;
  }
  check.inflation = hi;
  check.outcome = OdometryCheckOutcome::kDownweighted;
  return check;
}

}  // namespace dlslot::backend
