#include "calib.hpp"

namespace dlslot::sim {
namespace {

Pose rows(std::initializer_list<double> v) {
  Pose T = Pose::Identity();
  int i = 0;
  for (double x : v) {
    T.matrix()(i / 4, i % 4) = x;
    ++i;
  }
  return T;
}

}  // namespace

kitti::Calib kittiCalib() {
  kitti::Calib c;
  const double f = 7.215377e+02, cx = 6.095593e+02, cy = 1.728540e+02;
  c.P[0] << f, 0, cx, 0, 0, f, cy, 0, 0, 0, 1, 0;
  c.P[1] << f, 0, cx, -3.875744e+02, 0, f, cy, 0, 0, 0, 1, 0;
  c.P[2] << f, 0, cx, 4.485728e+01, 0, f, cy, 2.163791e-01, 0, 0, 1, 2.745884e-03;
  c.P[3] << f, 0, cx, -3.395242e+02, 0, f, cy, 2.199936e+00, 0, 0, 1, 2.729905e-03;
  c.R_rect << 9.999239e-01, 9.837760e-03, -7.445048e-03, -9.869795e-03, 9.999421e-01, -4.278459e-03, 7.402527e-03,
      4.351614e-03, 9.999631e-01;
  c.T_cam_velo = rows({7.533745e-03, -9.999714e-01, -6.166020e-04, -4.069766e-03, 1.480249e-02, 7.280733e-04,
                       -9.998902e-01, -7.631618e-02, 9.998621e-01, 7.523790e-03, 1.480755e-02, -2.717806e-01});
  c.T_velo_imu = rows({9.999976e-01, 7.553071e-04, -2.035826e-03, -8.086759e-01, -7.854027e-04, 9.998898e-01,
                       -1.482298e-02, 3.195559e-01, 2.024406e-03, 1.482454e-02, 9.998881e-01, -7.997231e-01});
  // The file's rotations are rounded to 7 digits; make them exactly orthonormal so that every
  // inverse taken later (Isometry3d::inverse transposes) is exact.
  auto orthonormal = [](const Eigen::Matrix3d& R) { return Eigen::Matrix3d(Eigen::Quaterniond(R).normalized()); };
  c.R_rect = orthonormal(c.R_rect);
  c.T_cam_velo.linear() = orthonormal(c.T_cam_velo.linear());
  c.T_velo_imu->linear() = orthonormal(c.T_velo_imu->linear());
  return c;
}

}  // namespace dlslot::sim
