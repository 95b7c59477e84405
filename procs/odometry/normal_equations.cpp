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
  bool statistics;
  void add(double s, NormalEquations& ne, double& w) const {
    if (s <= delta2) {
      ne.cost += 0.5 * s;
      if (statistics) {
        ne.sum_abs_inliers += std::sqrt(s);
        ++ne.num_inliers;
      }
      w = 1.0;
    } else {
      const double r = std::sqrt(s);
      ne.cost += 0.5 * (2.0 * delta * r - delta2);
      w = delta / r;
    }
  }
};

}  // namespace

NormalEquations linearize(const Matches& matches, const double* x, double huber_delta, bool inlier_statistics) {
  NormalEquations ne;
  RigidMotion motion;
  motion.at(x);
  const Eigen::Matrix3d& R = motion.rotation();
  const Eigen::Vector3d& t = motion.translation();
  const Eigen::Matrix3d& Jl = motion.leftJacobian();
  const Huber huber{huber_delta, huber_delta * huber_delta, inlier_statistics};
  // The Jacobian of T(x) p is [I, -[Rp]x Jl] (rigid_motion.hpp). Written per block rather than
  // as J^T J of the 3x6 / 1x6 Jacobians (edgeResidual / planeResidual, which the tests compare
  // with numeric differences): this pass runs ~6 times per solve over every correspondence.
  Eigen::Matrix3d Htt = Eigen::Matrix3d::Zero(), Htw = Eigen::Matrix3d::Zero(), Hww = Eigen::Matrix3d::Zero();
  Eigen::Vector3d gt = Eigen::Vector3d::Zero(), gw = Eigen::Vector3d::Zero();
  for (const EdgeMatch& m : matches.edges) {
    // r = P (q - a), P = I - u u^T; J = [P, -P C] with C = [Rp]x Jl. As P^2 = P and P r = r:
    // J^T J = [P, -P C; -C^T P, C^T P C] and J^T r = [r; -C^T r].
    const Eigen::Vector3d Rp = R * m.p;
    const Eigen::Vector3d d = Rp + t - m.a;
    const Eigen::Vector3d r = d - m.u * m.u.dot(d);
    double w;
    huber.add(r.squaredNorm(), ne, w);
    Eigen::Matrix3d C;
    for (int j = 0; j < 3; ++j) C.col(j) = Rp.cross(Jl.col(j));
    const Eigen::Matrix3d PC = C - m.u * (m.u.transpose() * C);
    Htt.noalias() += w * (Eigen::Matrix3d::Identity() - m.u * m.u.transpose());
    Htw.noalias() -= w * PC;
    Hww.noalias() += w * (C.transpose() * PC);
    gt += w * r;
    gw.noalias() -= w * (C.transpose() * r);
  }
  // Planes: J = [n^T, ((Rp) x n)^T Jl], a 1x6 row; only the upper triangle of w J^T J is summed.
  Matrix6d Hp = Matrix6d::Zero();
  Vector6d gp = Vector6d::Zero();
  for (const PlaneMatch& m : matches.planes) {
    const Eigen::Vector3d Rp = R * m.p;
    const double r = m.n.dot(Rp + t) + m.d;
    double w;
    huber.add(r * r, ne, w);
    Vector6d J;
    J << m.n, Jl.transpose() * Rp.cross(m.n);
    const Vector6d wJ = w * J;
    for (int j = 0; j < 6; ++j)
      for (int i = 0; i <= j; ++i) Hp(i, j) += wJ[i] * J[j];
    gp += r * wJ;
  }
  Hp.triangularView<Eigen::StrictlyLower>() = Hp.transpose();
  ne.H << Htt, Htw, Htw.transpose(), Hww;
  ne.H += Hp;
  ne.g << gt, gw;
  ne.g += gp;
  return ne;
}

}  // namespace dlslot::odometry
