#include "beam_index.hpp"

#include <algorithm>
#include <cmath>

namespace dlslot::odometry {

BeamModel::BeamModel(const FeatureConfig& cfg)
    : hdl64_(cfg.beam_model == "hdl64"),
      num_beams_(hdl64_ ? 64 : cfg.num_beams),
      min_deg_(cfg.min_vertical_deg),
      max_deg_(cfg.max_vertical_deg) {
  // Walk the angle down from straight up; where the beam changes, bisect for the exact step.
  const float step = 0.02f;  // below any beam spacing
  int beam = beamOfAngle(89.99f);
  for (int k = 1; 89.99f - k * step > -89.99f; ++k) {
    const float a = 89.99f - k * step;
    const int b = beamOfAngle(a);
    if (b != beam) {
      float lo = a, up = a + step;  // beamOfAngle(up) == beam, beamOfAngle(lo) == b
      for (int i = 0; i < 40; ++i) {
        const float mid = 0.5f * (lo + up);
        (beamOfAngle(mid) == beam ? up : lo) = mid;
      }
      // Angles >= up give `beam` (down to the previous step).
      tan_steps_.push_back(static_cast<float>(std::tan(up * M_PI / 180.0)));
      step_beams_.push_back(beam);
      beam = b;
    }
  }
  bottom_beam_ = beam;
  if (tan_steps_.empty()) return;
  lut_lo_ = tan_steps_.back() - 0.01f;
  lut_hi_ = tan_steps_.front() + 0.01f;
  const int bins = 16384;
  lut_scale_ = bins / (lut_hi_ - lut_lo_);
  lut_.resize(bins);
  // Each bin's beam at its centre (steps descend: [0, i) lie above t) ...
  size_t i = tan_steps_.size();
  for (int b = 0; b < bins; ++b) {
    const float tc = lut_lo_ + (b + 0.5f) / lut_scale_;
    while (i > 0 && tan_steps_[i - 1] <= tc) --i;
    lut_[b] = i == tan_steps_.size() ? bottom_beam_ : step_beams_[i];
  }
  // ... except around a step (with beamOf's rounding margin, doubled): there the steps decide.
  for (float st : tan_steps_) {
    const float margin = 2e-5f * (std::abs(st) + 1e-3f);
    const int b0 = std::max(0, static_cast<int>(std::floor((st - margin - lut_lo_) * lut_scale_)) - 1);
    const int b1 = std::min(bins - 1, static_cast<int>(std::floor((st + margin - lut_lo_) * lut_scale_)) + 1);
    for (int b = b0; b <= b1; ++b) lut_[b] = kAmbiguous;
  }
}

int BeamModel::beamOfAngle(float angle) const {
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

int BeamModel::beamOf(const Eigen::Vector3f& p) const {
  const float horizontal = std::sqrt(p.x() * p.x() + p.y() * p.y());
  const float t = p.z() / horizontal;
  if (t >= lut_lo_ && t < lut_hi_) {
    const int b = std::min(static_cast<int>((t - lut_lo_) * lut_scale_), static_cast<int>(lut_.size()) - 1);
    if (lut_[b] != kAmbiguous) return lut_[b];
  }
  return stepsBeam(t, p, horizontal);
}

int BeamModel::stepsBeam(float t, const Eigen::Vector3f& p, float horizontal) const {
  // tan_steps_ descends: the first step at or below t.
  const auto it = std::lower_bound(tan_steps_.begin(), tan_steps_.end(), t, [](float s, float v) { return s > v; });
  const size_t i = it - tan_steps_.begin();
  // Within rounding of a step, the rule decides on the angle itself, as it always did.
  auto near = [t](float s) { return std::abs(t - s) <= 1e-5f * (std::abs(s) + 1e-3f); };
  if ((i < tan_steps_.size() && near(tan_steps_[i])) || (i > 0 && near(tan_steps_[i - 1])))
    return beamOfAngle(std::atan2(p.z(), horizontal) * static_cast<float>(180.0 / M_PI));
  return i == tan_steps_.size() ? bottom_beam_ : step_beams_[i];
}

}  // namespace dlslot::odometry
