// Which laser (beam) of a spinning LiDAR a point came from, from its vertical angle. Curvature
// and feature selection work along one beam's ring, so every point needs its beam.
#pragma once

#include <Eigen/Core>

#include "odometry_config.hpp"

namespace dlslot::odometry {

class BeamModel {
 public:
  explicit BeamModel(const FeatureConfig& cfg);
  int numBeams() const { return num_beams_; }
  // Beam index (0 = top) of a point in the lidar frame, or -1 when outside the model's beams.
  int beamOf(const Eigen::Vector3f& p) const;

 private:
  bool hdl64_;
  int num_beams_;
  double min_deg_, max_deg_;
};

}  // namespace dlslot::odometry
