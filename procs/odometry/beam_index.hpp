// Which laser (beam) of a spinning LiDAR a point came from, from its vertical angle. Curvature
// and feature selection work along one beam's ring, so every point needs its beam.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "odometry_config.hpp"

namespace dlslot::odometry {

class BeamModel {
 public:
  explicit BeamModel(const FeatureConfig& cfg);
  int numBeams() const { return num_beams_; }
  // Beam index (0 = top) of a point in the lidar frame, or -1 when outside the model's beams.
  // The beam is a step function of the vertical angle, so it is looked up among the steps'
  // tangents (z / horizontal range), without the atan2 per point (5 % of the odometry's
  // instructions on the real slice).
  int beamOf(const Eigen::Vector3f& p) const;
  // The rule itself, from the vertical angle in degrees.
  int beamOfAngle(float deg) const;

 private:
  bool hdl64_;
  int num_beams_;
  double min_deg_, max_deg_;
  // Steps from the top: points with tan(angle) >= tan_steps_[i] (and below the previous step)
  // get step_beams_[i]; below the last step: bottom_beam_.
  std::vector<float> tan_steps_;
  std::vector<int> step_beams_;
  int bottom_beam_ = -1;
  // Uniform bins over [lut_lo_, lut_hi_) of tan(angle): the beam of a bin no step crosses, or
  // kAmbiguous (then the steps decide): one multiply and one load for nearly every point.
  static constexpr int kAmbiguous = -2;
  std::vector<int> lut_;
  float lut_lo_ = 0.0f, lut_hi_ = 0.0f, lut_scale_ = 0.0f;
  int stepsBeam(float t, const Eigen::Vector3f& p, float horizontal) const;
};

}  // namespace dlslot::odometry
