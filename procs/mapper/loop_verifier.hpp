// Verifying a loop candidate: the two keyframes' clouds registered (PCL's generalized ICP,
// Segal et al. 2009), then a strict acceptance test. A false loop bends the whole trajectory, a
// missed one only leaves drift, so a candidate must pass all of:
//   1. overlap: of the query's structure (points off the ground) within overlap_radius_m of the
//      match keyframe (where the match side sees densely: a place passed again tens of metres away
//      overlaps only there) and where the match side saw something (a match point within
//      support_distance_m), most lies within inlier_distance of the match after alignment, with a
//      small RMS distance (a wrong pose: about inlier / support distance of it, by chance);
//   2. drift bound: the registration moves the query at most 1 m + max_drift_fraction x the path
//      driven since the match (and 2 deg + 1 deg per 100 m) away from where the odometry puts it:
//      anything farther is not drift but a wrong place;
//   The registration runs from several starts (the prior and starts shifted along the query's x and
//   y within the drift bound) and keeps the result the overlap measure scores best: from the
//   odometry's estimate alone GICP can slide along a street into a wrong minimum.
//   3. uniqueness: registrations started ambiguity_shift_m off along x and y must come back to
//      the same pose, or end clearly worse. Guard rails with posts, rows of parked cars and
//      corridors align equally well at several shifts; such a place cannot tell where along
//      it the vehicle is, so it is refused.
//   4. localisation: the accepted pose moved false_loop_m (1 m, the error that makes a loop false)
//      along the match keyframe's x or y must lose inliers (keep fewer than ambiguity_ratio of them).
//      A place whose structure is nearly all along the road (rails, kerbs, a long wall) aligns
//      as well 1 m further on; test 3 finds no other pose there (one broad minimum, not two), but
//      the registration's error along the road can reach a metre (a highway under forced
//      candidates: accepted edges 1.05-1.07 m off).
#pragma once

#include <string>
#include <vector>

#include "dlslot/types.hpp"
#include "mapper/mapper_config.hpp"

namespace dlslot::mapper {

struct Registration {
  Pose T_match_query = Pose::Identity();
  bool converged = false;
  // Of the query's points off the ground near the match keyframe, the share where the match side saw
  // something (a match point within support_distance) ...
  double support_ratio = 0;
  // ... and of those, the share within inlier_distance of the match.
  double inlier_ratio = 0;
  double rmse_m = 0;        // RMS distance of those inliers
  int inliers = 0;          // their number
};

struct RegistrationStart {
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();  // the start: the prior moved by this along the query's axes
  Registration result;
};

struct LoopVerdict {
  bool accepted = false;
  std::string reason;  // the failed test, "" when accepted
  Registration registration;                         // the kept result (tests 1-4 judge it)
  Eigen::Vector3d start_shift = Eigen::Vector3d::Zero();  // the start it came from
  std::vector<RegistrationStart> starts;             // every start's result, the direct one first
  double shifted_inlier_share = 0;  // test 4: the most inliers kept with the pose moved false_loop_m (0: not reached)
};

// Clouds: x y z columns in each keyframe's lidar frame (intensity unused).
Registration registerClouds(const PointCloud& query, const PointCloud& match, const Pose& initial,
                            const LoopConfig& config);

// prior: T_match_query from the current trajectory estimate; path_m: distance driven between them.
LoopVerdict verifyLoop(const PointCloud& query, const PointCloud& match, const Pose& prior, double path_m,
                       const LoopConfig& config);

// Points below this height in the lidar frame are the road: they align at any shift along it, so
// they take part in the registration but not in the overlap and uniqueness scores.
inline constexpr double kGroundBelowZ = -1.3;

}  // namespace dlslot::mapper
