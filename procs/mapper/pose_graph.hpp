// The keyframe pose graph: nodes are keyframe poses T_map_keyframe, edges are odometry and loop
// measurements (relative_pose_factor.hpp), solved with Ceres. The first keyframe is held fixed
// (the gauge: the map frame is the odometry world at the first keyframe).
#pragma once

#include <vector>

#include "mapper/relative_pose_factor.hpp"

namespace dlslot::mapper {

class PoseGraph {
 public:
  // loss_sigmas: the Cauchy loss scale of loop edges, in sigmas.
  explicit PoseGraph(double loss_sigmas = 10.0) : loss_sigmas_(loss_sigmas) {}
  int addNode(const Pose& initial);
  void addOdometryEdge(int a, int b, const Pose& T_ab, const Vector6d& sigma);
  void addLoopEdge(int a, int b, const Pose& T_ab, const Vector6d& sigma);
  // Solves; returns the final cost. Poses are updated in place.
  double optimize(int max_iterations = 100);
  int size() const { return static_cast<int>(nodes_.size()); }
  Pose pose(int i) const;
  std::vector<Pose> poses() const;
  int loopEdges() const { return static_cast<int>(loops_.size()); }

 private:
  struct Node {
    Eigen::Vector3d p;
    Eigen::Quaterniond q;
  };
  struct Edge {
    int a, b;
    Pose T_ab;
    Vector6d sigma;
  };
  double loss_sigmas_;
  std::vector<Node> nodes_;
  std::vector<Edge> odometry_, loops_;
};

}  // namespace dlslot::mapper
