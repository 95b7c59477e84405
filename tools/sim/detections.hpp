// The simulated 3D object detector: each object is found with a probability that grows with its
// number of points, its box comes back with noise on position (growing with range), yaw (and
// now and then a heading flipped by pi) and size, vans are sometimes called cars; false positives
// come from random structure and, persistently, from a few poles, trees and bushes that "look
// like" pedestrians. Scores are SECOND-like probabilities: high for well-seen objects, low for
// false positives. Rows use the KITTI tracking result format (truncated and occluded -1);
// true positives carry the object's track id (for analysis only), false positives -1.
#pragma once

#include <vector>

#include "dlslot/kitti.hpp"
#include "rng.hpp"
#include "sensor.hpp"

namespace dlslot::sim {

struct DetectorTarget {
  Box box;            // lidar frame (type set)
  int track_id = -1;  // -1 when not (yet) labelled
  int points = 0;
  Eigen::Vector2d drift = Eigen::Vector2d::Zero();  // driftProcess of this object now (along, across)
};

// Two independent unit-variance random processes of time (s), component c correlated by
// exp(-|dt| / time_s[c]), the same for the same key: a sum of cosines whose frequencies are drawn
// from that correlation's spectrum (a Cauchy distribution of scale 1 / time_s[c]), so any frame can
// be drawn alone.
Eigen::Vector2d driftProcess(uint64_t key, double t_s, const Eigen::Vector2d& time_s);

// Which structures are persistent false-positive sources, chosen once per sequence.
std::vector<bool> chooseGhosts(const World& world, const DetectorSpec& spec, uint64_t key);

std::vector<kitti::LabelRow> detect(int frame, const std::vector<DetectorTarget>& targets, const Scan& scan,
                                    const World& world, const std::vector<bool>& ghosts, const Pose& T_map_lidar,
                                    const DetectorSpec& spec, const kitti::Calib& calib, Rng& rng);

}  // namespace dlslot::sim
