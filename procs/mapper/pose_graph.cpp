#include "mapper/pose_graph.hpp"

#include <ceres/ceres.h>

#include <stdexcept>

namespace dlslot::mapper {

int PoseGraph::addNode(const Pose& T) {
  nodes_.push_back({T.translation(), Eigen::Quaterniond(T.rotation()).normalized()});
  return size() - 1;
}

void PoseGraph::addOdometryEdge(int a, int b, const Pose& T_ab, const Vector6d& sigma) {
  if (a < 0 || b < 0 || a >= size() || b >= size()) throw std::out_of_range("PoseGraph: odometry edge to a missing node");
  odometry_.push_back({a, b, T_ab, sigma});
}

void PoseGraph::addLoopEdge(int a, int b, const Pose& T_ab, const Vector6d& sigma) {
  if (a < 0 || b < 0 || a >= size() || b >= size()) throw std::out_of_range("PoseGraph: loop edge to a missing node");
  loops_.push_back({a, b, T_ab, sigma});
}

double PoseGraph::optimize(int max_iterations) {
  // Each loop edge's residual is in units of its sigma.
  if (nodes_.size() < 2) return 0.0;
  ceres::Problem problem;
  auto add = [&](const Edge& e, ceres::CostFunction* f, ceres::LossFunction* loss) {
    problem.AddResidualBlock(f, loss, nodes_[e.a].p.data(), nodes_[e.a].q.coeffs().data(), nodes_[e.b].p.data(),
                             nodes_[e.b].q.coeffs().data());
  };
  for (const Edge& e : odometry_) add(e, OdometryEdgeFactor::Create(e.T_ab, e.sigma), nullptr);
  // Cauchy: a loop edge that disagrees with the rest of the graph by many more than loss_sigmas
  // of its own sigmas loses its pull (one of two conflicting loops); below that it is nearly
  // quadratic, so a true loop pulls the drifted trajectory in from well outside its sigma.
  for (const Edge& e : loops_) add(e, LoopEdgeFactor::Create(e.T_ab, e.sigma), new ceres::CauchyLoss(loss_sigmas_));
  for (Node& n : nodes_)
    if (problem.HasParameterBlock(n.q.coeffs().data()))
      problem.SetManifold(n.q.coeffs().data(), new ceres::EigenQuaternionManifold);
  if (problem.HasParameterBlock(nodes_[0].p.data())) {
    problem.SetParameterBlockConstant(nodes_[0].p.data());
    problem.SetParameterBlockConstant(nodes_[0].q.coeffs().data());
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  options.max_num_iterations = max_iterations;
  options.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  for (Node& n : nodes_) n.q.normalize();
  return summary.final_cost;
}

Pose PoseGraph::pose(int i) const {
  Pose T = Pose::Identity();
  T.linear() = nodes_.at(i).q.toRotationMatrix();
  T.translation() = nodes_.at(i).p;
  return T;
}

std::vector<Pose> PoseGraph::poses() const {
  std::vector<Pose> out;
  out.reserve(nodes_.size());
  for (int i = 0; i < size(); ++i) out.push_back(pose(i));
  return out;
}

}  // namespace dlslot::mapper
