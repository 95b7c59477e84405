// Where the velocity error comes from: the matched pairs' velocity errors grouped by the track's
// age, the label's class, whether the label moves, its range and the part of the sequence (a single
// RMSE hides whether young tracks, far objects or one bad stretch dominate it).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace dlslot::eval {

// One matched label/track pair with a velocity on both sides (m/s, the scan's lidar axes).
struct VelocityPair {
  int frame_index = 0;  // position of the scan in the evaluated sequence (0-based)
  int label_id = -1, track_id = -1;
  std::string type;     // the label's class
  bool dynamic = false;  // the label moves (velocity.hpp: markDynamicLabels)
  int track_age = 0;     // scans since the track was first output (0 = its first scan)
  Eigen::Vector2d truth = Eigen::Vector2d::Zero(), track = Eigen::Vector2d::Zero();
  std::optional<Eigen::Matrix2d> track_covariance = std::nullopt;  // the track's own, when it gave one
  double range_m = 0;    // the label's horizontal distance from the sensor
  double error() const { return (truth - track).norm(); }
  // e^T C^-1 e: the squared error in the track's own standard deviations (chi-square with 2
  // degrees of freedom when the covariance is honest); none without a positive-definite one.
  std::optional<double> nees() const;
};

struct VelocityGroup {
  std::string dimension;  // "age", "class", "motion", "range", "frames"
  std::string bin;        // e.g. "0-4", "car", "dynamic", "20-40", "000-029"
  int pairs = 0;
  std::optional<double> rmse_mps, mean_mps, p90_mps;
};

// Groups: track age 0-4 / 5-9 / 10-19 / 20+ scans, each class, dynamic / static, range 0-20 /
// 20-40 / 40-60 / 60+ m (a detector's boxes and the points on an object both worsen with range),
// and ten equal stretches of the sequence (num_frames scans). Age, class, range and frame groups
// hold dynamic labels only (as the velocity RMSE does); the motion groups hold both.
std::vector<VelocityGroup> breakdownVelocityErrors(const std::vector<VelocityPair>& pairs, int num_frames);

// Whether the tracks' velocity covariances tell the size of their errors: over the dynamic pairs
// of tracks aged min_age..max_age scans with a covariance, the mean NEES (2 when honest) and the
// share of errors inside the covariance's 95 % ellipse (NEES <= 5.991, chi-square with 2 degrees
// of freedom: 0.95 when honest; lower, overconfident).
struct VelocityCalibration {
  int pairs = 0;
  std::optional<double> nees_mean, within_95;
};
VelocityCalibration velocityCalibration(const std::vector<VelocityPair>& pairs, int min_age, int max_age);

// The velocity error in bins, for the plots: each bin's RMSE over its dynamic pairs beside the RMS
// error the tracks' own covariances predict (sqrt of the mean trace over the pairs with one): where
// the two part, the published covariance misjudges those tracks. Bins with fewer than min_pairs
// pairs are left out (an RMSE of n errors is uncertain by about 1 / sqrt(2n) of itself).
struct VelocityBin {
  double from = 0, to = 0;  // what the bin holds: range in m, or track age in scans
  int pairs = 0;
  double rmse_mps = 0;
  std::optional<double> own_rms_mps;  // none when no pair of the bin has a covariance
};
// By the label's range, bins of bin_m metres, over tracks aged min_age..max_age scans.
std::vector<VelocityBin> velocityErrorByRange(const std::vector<VelocityPair>& pairs, double bin_m, int min_age,
                                              int max_age, int min_pairs);
// By the track's age, one bin a scan up to last_age, which holds every older track too.
std::vector<VelocityBin> velocityErrorByAge(const std::vector<VelocityPair>& pairs, int last_age, int min_pairs);

}  // namespace dlslot::eval
