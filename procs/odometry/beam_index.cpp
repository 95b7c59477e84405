#include "beam_index.hpp"

#include <cmath>

namespace dlslot::odometry {

BeamModel::BeamModel(const FeatureConfig& cfg)
    : hdl64_(cfg.beam_model == "hdl64"),
      num_beams_(hdl64_ ? 64 : cfg.num_beams),
      min_deg_(cfg.min_vertical_deg),
      max_deg_(cfg.max_vertical_deg) {}

int BeamModel::beamOf(const Eigen::Vector3f& p) const {
  const float angle = std::atan2(p.z(), std::sqrt(p.x() * p.x() + p.y() * p.y())) * static_cast<float>(180.0 / M_PI);
  if (hdl64_) {
    // A-LOAM's rule for the KITTI HDL-64E: the upper block spaced ~1/3 deg, the lower ~1/2 deg;
    // like A-LOAM, beams past 50 (the steepest, mostly the ego vehicle's surroundings) are unused.
    if (angle > 2.0f || angle < -24.33f) return -1;
    const int beam = angle >= -8.83f ? static_cast<int>((2.0f - angle) * 3.0f + 0.5f)
                                     : 32 + static_cast<int>((-8.83f - angle) * 2.0f + 0.5f);
    return beam >= 0 && beam <= 50 ? beam : -1;
  }
  const double step = (max_deg_ - min_deg_) / std::max(1, num_beams_ - 1);
  const long beam = std::lround((max_deg_ - angle) / step);
  return beam >= 0 && beam < num_beams_ ? static_cast<int>(beam) : -1;
}

}  // namespace dlslot::odometry
