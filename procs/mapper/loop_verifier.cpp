// GCC 12 warns (-Warray-bounds, in xmmintrin.h) inside the headers this file instantiates: PCL
// 1.13's GICP and SVD code assign Eigen 3-vectors into blocks of 4x4 matrices whose size is known
// only at run time, and Eigen's copy has a 16-byte SSE path for blocks of 4 or more, which a
// 12-byte vector reaches past. The block is 3 long, so that path never runs; GCC cannot prove it
// (a known false positive of GCC 12 on Eigen). Silenced for the headers only: their lines lie
// between push and pop, and a middle-end warning is judged at the line it points to; this file's
// own code is still checked.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Warray-bounds"
#include "mapper/loop_verifier.hpp"

#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_types.h>
#include <pcl/registration/gicp.h>
#pragma GCC diagnostic pop

#include <algorithm>
#include <cmath>
#include <sstream>

namespace dlslot::mapper {
namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;

Cloud::Ptr toPcl(const PointCloud& points) {
  Cloud::Ptr c(new Cloud);
  c->reserve(points.cols());
  for (Eigen::Index i = 0; i < points.cols(); ++i) c->push_back(pcl::PointXYZ(points(0, i), points(1, i), points(2, i)));
  return c;
}

// Overlap of the query's structure with the match after T_match_query: of the query's structure
// points near the match keyframe that lie where the match side saw something (a match point
// within support_m), the share within inlier_m of the match. The match side sees only part of what
// the query sees (a place passed again 35 m off: other faces, other gaps between buildings), and
// how much varies from place to place, so the share of all of the query's points says as much
// about that as about the alignment; among the points the match side saw, a right pose puts most
// on its surfaces, a wrong one about inlier_m / support_m of them (their distances to the nearest
// surface spread evenly up to support_m).
void score(const PointCloud& query, const pcl::KdTreeFLANN<pcl::PointXYZ>& tree, const Pose& T, double inlier_m,
           double support_m, double radius_m, Registration& r) {
  int structure = 0, supported = 0, inliers = 0;
  double sq = 0;
  std::vector<int> index(1);
  std::vector<float> d2(1);
  for (Eigen::Index i = 0; i < query.cols(); ++i) {
    if (query(2, i) < kGroundBelowZ) continue;
    const Eigen::Vector3d p = T * query.col(i).head<3>().cast<double>();
    if (p.head<2>().norm() > radius_m) continue;  // where the match side sees densely
    ++structure;
    if (tree.nearestKSearch(pcl::PointXYZ(p.x(), p.y(), p.z()), 1, index, d2) != 1 || d2[0] > support_m * support_m)
      continue;
    ++supported;
    if (d2[0] <= inlier_m * inlier_m) {
      ++inliers;
      sq += d2[0];
    }
  }
  r.inliers = inliers;
  r.inlier_ratio = supported ? double(inliers) / supported : 0.0;
  r.support_ratio = structure ? double(supported) / structure : 0.0;
  r.rmse_m = inliers ? std::sqrt(sq / inliers) : 0.0;
}

Registration align(const Cloud::Ptr& query, const Cloud::Ptr& match, const PointCloud& query_points,
                   const pcl::KdTreeFLANN<pcl::PointXYZ>& tree, const Pose& initial, const LoopConfig& c) {
  pcl::GeneralizedIterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> gicp;
  gicp.setInputSource(query);
  gicp.setInputTarget(match);
  gicp.setMaximumIterations(50);
  gicp.setTransformationEpsilon(1e-6);
  Cloud aligned;
  // Coarse to fine: the drift a loop undoes can be metres (urban-loop's end is ~3 m off after
  // 1.6 km), beyond the reach of the usual correspondence distance; the last, short reach keeps
  // far pairs (other surfaces) from pulling the result off by tenths of a metre.
  Eigen::Matrix4f T = initial.matrix().cast<float>();
  bool converged = true;
  for (const double reach : {c.coarse_correspondence_m, c.max_correspondence_m, c.fine_correspondence_m}) {
    gicp.setMaxCorrespondenceDistance(reach);
    gicp.align(aligned, T);
    converged = gicp.hasConverged();
    T = gicp.getFinalTransformation();
  }
  Registration r;
  r.converged = converged;
  r.T_match_query.matrix() = T.cast<double>();
  r.T_match_query.linear() = Eigen::Quaterniond(r.T_match_query.rotation()).normalized().toRotationMatrix();
  score(query_points, tree, r.T_match_query, c.inlier_distance_m, c.support_distance_m, c.overlap_radius_m, r);
  return r;
}

double angleDeg(const Eigen::Matrix3d& R) { return Eigen::AngleAxisd(R).angle() * 180.0 / M_PI; }

}  // namespace

Registration registerClouds(const PointCloud& query, const PointCloud& match, const Pose& initial, const LoopConfig& c) {
  const Cloud::Ptr q = toPcl(query), m = toPcl(match);
  pcl::KdTreeFLANN<pcl::PointXYZ> tree;
  tree.setInputCloud(m);
  return align(q, m, query, tree, initial, c);
}

LoopVerdict verifyLoop(const PointCloud& query, const PointCloud& match, const Pose& prior, double path_m,
                       const LoopConfig& c) {
  LoopVerdict v;
  if (query.cols() < 100 || match.cols() < 100) {
    v.reason = "too few points";
    return v;
  }
  const Cloud::Ptr q = toPcl(query), m = toPcl(match);
  pcl::KdTreeFLANN<pcl::PointXYZ> tree;
  tree.setInputCloud(m);
  const double max_t = 1.0 + c.max_drift_fraction * path_m, max_r = 2.0 + path_m / 100.0;
  auto withinDrift = [&](const Pose& T) {
    const Pose change = prior.inverse() * T;
    return change.translation().norm() <= max_t && angleDeg(change.rotation()) <= max_r;
  };
  // Several starts: GICP from the odometry's estimate can slide along a street into a wrong
  // minimum when the drift is metres. The query may lie anywhere within the drift bound (test 2),
  // so starts shifted start_step_m, 2 x start_step_m, ... along the query's x and y (the street's
  // directions; the coarse stage's reach covers the space between them), those within the bound
  // only, are registered too; the result the overlap measure (test 1) scores best is kept. The
  // direct start's result stays unless another lands elsewhere (> 0.5 m away) with a higher score,
  // so where it was right nothing changes; a wrong pose that wins is still refused by tests 1-3.
  auto valid = [&](const Registration& r) { return r.converged && withinDrift(r.T_match_query); };
  Registration best = align(q, m, query, tree, prior, c);
  v.starts.push_back({Eigen::Vector3d::Zero(), best});
  for (int k = 1; k <= c.start_steps; ++k) {
    const double s = k * c.start_step_m;
    if (s > max_t) break;
    for (const Eigen::Vector3d& shift : {Eigen::Vector3d(s, 0, 0), Eigen::Vector3d(-s, 0, 0), Eigen::Vector3d(0, s, 0),
                                        Eigen::Vector3d(0, -s, 0)}) {
      const Registration alt = align(q, m, query, tree, prior * Eigen::Translation3d(shift), c);
      v.starts.push_back({shift, alt});
      if (!valid(alt)) continue;
      const double apart = (alt.T_match_query.translation() - best.T_match_query.translation()).norm();
      if (!valid(best) || (apart > 0.5 && alt.inlier_ratio > best.inlier_ratio)) {
        best = alt;
        v.start_shift = shift;
      }
    }
  }
  v.registration = best;
  std::ostringstream why;
  if (!best.converged) {
    v.reason = "registration did not converge";
    return v;
  }
  if (best.inlier_ratio < c.min_inlier_ratio || best.rmse_m > c.max_rmse_m) {
    why.precision(3);
    why << "overlap: inlier ratio " << best.inlier_ratio << " (min " << c.min_inlier_ratio << ") of the "
        << best.support_ratio << " the match side saw, rmse " << best.rmse_m << " m (max " << c.max_rmse_m << ")";
    v.reason = why.str();
    return v;
  }
  if (!withinDrift(best.T_match_query)) {
    const Pose change = prior.inverse() * best.T_match_query;
    why.precision(3);
    why << "drift bound: the registration moves the query " << change.translation().norm() << " m / "
        << angleDeg(change.rotation()) << " deg from the odometry's estimate (max " << max_t << " m / " << max_r
        << " deg after " << path_m << " m)";
    v.reason = why.str();
    return v;
  }
  // Uniqueness: from starts shifted along the query's x and y, the registration must return to
  // the same pose or end clearly worse.
  for (const Eigen::Vector3d& shift : {Eigen::Vector3d(c.ambiguity_shift_m, 0, 0), Eigen::Vector3d(-c.ambiguity_shift_m, 0, 0),
                                      Eigen::Vector3d(0, c.ambiguity_shift_m, 0), Eigen::Vector3d(0, -c.ambiguity_shift_m, 0)}) {
    const Pose start = best.T_match_query * Eigen::Translation3d(shift);
    const Registration alt = align(q, m, query, tree, start, c);
    const double apart = (alt.T_match_query.translation() - best.T_match_query.translation()).norm();
    if (apart > 0.5 && alt.inlier_ratio >= c.ambiguity_ratio * best.inlier_ratio) {
      why.precision(3);
      why << "ambiguous: a start " << shift.norm() << " m off ends " << apart << " m away with inlier ratio "
          << alt.inlier_ratio << " (best " << best.inlier_ratio << ")";
      v.reason = why.str();
      return v;
    }
  }
  // Localisation: the accepted pose moved false_loop_m (the error that makes a loop false) along the
  // match keyframe's x or y must lose inliers; keeping ambiguity_ratio of them or more, it is as good
  // as the pose, and the place cannot tell a false loop from a right one (a straight road between
  // guard rails: the rails align at any shift along them).
  for (const Eigen::Vector3d& shift : {Eigen::Vector3d(c.false_loop_m, 0, 0), Eigen::Vector3d(-c.false_loop_m, 0, 0),
                                      Eigen::Vector3d(0, c.false_loop_m, 0), Eigen::Vector3d(0, -c.false_loop_m, 0)}) {
    Registration moved;
    score(query, tree, Eigen::Translation3d(shift) * best.T_match_query, c.inlier_distance_m, c.support_distance_m,
          c.overlap_radius_m, moved);
    v.shifted_inlier_share = std::max(v.shifted_inlier_share, best.inliers ? double(moved.inliers) / best.inliers : 1.0);
  }
  if (v.shifted_inlier_share >= c.ambiguity_ratio) {
    why.precision(3);
    why << "not localised: moved " << c.false_loop_m << " m along x or y it keeps " << v.shifted_inlier_share
        << " of its inliers (max " << c.ambiguity_ratio << ")";
    v.reason = why.str();
    return v;
  }
  v.accepted = true;
  return v;
}

}  // namespace dlslot::mapper
