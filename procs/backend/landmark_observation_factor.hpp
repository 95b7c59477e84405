// Landmark observation factor: a static object is one landmark pose L for the whole window,
// observed from every ego pose that detects it (paper III-D): e = (X_t^-1 L)^-1 b_t, the form
// of eq. 9 with its own information (a parked car's box is steadier than a moving one's).
#pragma once

#include "backend/observation_factor.hpp"

namespace dlslot::backend {

class LandmarkObservationFactor final : public ObservationFactor {
 public:
  using ObservationFactor::ObservationFactor;  // parameters: X_t, L
  static ceres::CostFunction* Create(const Pose& b, const Matrix6& sqrt_info) {
    return new LandmarkObservationFactor(b, sqrt_info);
  }
};

}  // namespace dlslot::backend
