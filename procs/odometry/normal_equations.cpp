#include "normal_equations.hpp"

#include <cmath>

namespace dlslot::odometry {

// r = (I - u u^T)(T p - a): the perpendicular offset from the line.
Eigen::Vector3d edgeResidual(const EdgeMatch& m, const RigidMotion& motion, Matrix36d* J) {
  const Eigen::Vector3d d = motion.apply(m.p, J) - m.a;
  if (J) *J -= m.u * (m.u.transpose() * *J);
  return d - m.u * m.u.dot(d);
}

// r = n . (T p) + d: the signed distance from the plane.
double planeResidual(const PlaneMatch& m, const RigidMotion& motion, Eigen::Matrix<double, 1, 6>* J) {
  Matrix36d Jq;
  const Eigen::Vector3d q = motion.apply(m.p, J ? &Jq : nullptr);
  if (J) *J = m.n.transpose() * Jq;
  return m.n.dot(q) + m.d;
}

namespace {

// Huber's rho(s) for s = |r|^2 (Ceres' HuberLoss) and its weight rho'(s): 1 inside delta,
// delta / |r| outside. Ceres' Corrector uses exactly sqrt(rho') as the scaling for Huber
// (rho'' <= 0), so this is the same iteratively reweighted problem.
struct Huber {
  double delta, delta2;
  void add(double s, NormalEquations& ne, double& w) const {
    if (s <= delta2) {
      ne.cost += 0.5 * s;
      ne.sum_abs_inliers += std::sqrt(s);
      ++ne.num_inliers;
      w = 1.0;
    } else {
      const double r = std::sqrt(s);
      ne.cost += 0.5 * (2.0 * delta * r - delta2);
      w = delta / r;
    }
  }
};

}  // namespace

NormalEquations linearize(const Matches& matches, const double* x, double huber_delta) {
  NormalEquations ne;
  RigidMotion motion;
  motion.at(x);
  const Huber huber{huber_delta, huber_delta * huber_delta};
  // Only the upper triangle is accumulated; mirrored at the end.
  Matrix36d J;
  for (const EdgeMatch& m : matches.edges) {
    const Eigen::Vector3d r = edgeResidual(m, motion, &J);
    double w;
    huber.add(r.squaredNorm(), ne, w);
    ne.H.triangularView<Eigen::Upper>() += w * J.transpose() * J;
    ne.g.noalias() += w * J.transpose() * r;
  }
  Eigen::Matrix<double, 1, 6> Jp;
  for (const PlaneMatch& m : matches.planes) {
    const double r = planeResidual(m, motion, &Jp);
    double w;
    huber.add(r * r, ne, w);
    ne.H.triangularView<Eigen::Upper>() += w * Jp.transpose() * Jp;
    ne.g.noalias() += (w * r) * Jp.transpose();
  }
  ne.H.triangularView<Eigen::StrictlyLower>() = ne.H.transpose();
  return ne;
}

}  // namespace dlslot::odometry
