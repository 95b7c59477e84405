#include "curvature.hpp"

namespace dlslot::odometry {

Eigen::VectorXf ringCurvature(const Eigen::Ref<const Eigen::Matrix3Xf>& ring, int half_window) {
  const Eigen::Index n = ring.cols(), w = half_window;
  Eigen::VectorXf c = Eigen::VectorXf::Constant(n, -1.0f);
  if (n < 2 * w + 1) return c;
  // A sliding window sum keeps this O(n) whatever the window (in double: no drift over a ring).
  Eigen::Vector3d window = ring.leftCols(2 * w + 1).cast<double>().rowwise().sum();
  for (Eigen::Index i = w; i + w < n; ++i) {
    if (i > w) window += (ring.col(i + w) - ring.col(i - w - 1)).cast<double>();
    c[i] = static_cast<float>((window - static_cast<double>(2 * w + 1) * ring.col(i).cast<double>()).squaredNorm());
  }
  return c;
}

}  // namespace dlslot::odometry
