#include "degeneracy.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>

namespace dlslot::odometry {

TranslationConstraint translationConstraint(const Matrix6d& H) {
  TranslationConstraint c;
  const Eigen::Matrix3d Htt = H.topLeftCorner<3, 3>(), Htw = H.topRightCorner<3, 3>(),
                        Hww = H.bottomRightCorner<3, 3>();
  // Hww is positive definite whenever the scan has structure at more than one range; a rank-
  // deficient one (nothing constrains a rotation) leaves Htt as it is along that rotation's
  // coupling, which LDLT's pseudo-solve does not blow up.
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(Hww);
  Eigen::Matrix3d S = Htt;
  if (ldlt.info() == Eigen::Success && ldlt.isPositive()) S -= Htw * ldlt.solve(Htw.transpose());
  S = 0.5 * (S + S.transpose());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(S);
  if (eig.info() != Eigen::Success) return c;
  c.information = eig.eigenvalues().cwiseMax(0.0);
  c.directions = eig.eigenvectors();
  return c;
}

double chiSquareAlong(const Eigen::Vector3d& d, const Eigen::Vector3d& v, const Eigen::Matrix3d& Ca,
                      const Eigen::Matrix3d& Cb) {
  const double along = v.dot(d);
  const double var = v.dot((Ca + Cb) * v);
  return var > 0 ? along * along / var : 0.0;
}

}  // namespace dlslot::odometry
