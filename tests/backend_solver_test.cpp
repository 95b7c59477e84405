// The WindowSolver against Ceres' own solver on the same small window (ego poses, a landmark,
// a dynamic object chain, a prior): the same minimum, and the same marginal covariances.
#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <random>

#include "backend/backend_config.hpp"
#include "backend/constant_velocity_factor.hpp"
#include "backend/landmark_observation_factor.hpp"
#include "backend/marginalization_prior.hpp"
#include "backend/observation_factor.hpp"
#include "backend/odometry_factor.hpp"
#include "backend/pose_change_factor.hpp"
#include "backend/window_solver.hpp"
#include "backend_scene.hpp"

using namespace dlslot;
using namespace dlslot::backend;
using dlslot::backend::test::planarPose;

namespace {

Pose noisy(const Pose& T, std::mt19937& rng, double t, double r) {
  std::normal_distribution<double> n(0.0, 1.0);
  Vector6 d;
  d << t * n(rng), t * n(rng), t * n(rng), r * n(rng), r * n(rng), r * n(rng);
  return plus(T, d);
}

struct Window {
  std::vector<Vector7> ego, object, change;
  Vector7 landmark;
  std::vector<Factor> factors;
  std::vector<double*> separator;  // ego poses, landmark, newest ego pose last
  std::vector<std::vector<double*>> groups;
};

// 6 ego poses driving forward and turning, a parked car seen from all, a car moving ahead
// seen from all; measurements with noise, states started away from the truth.
void build(Window& w, unsigned seed) {
  std::mt19937 rng(seed);
  auto ego = [](int i) { return planarPose(5.0 * i, 0.2 * i * i, 0.05 * i); };
  auto car = [](int i) { return planarPose(12.0 + 6.0 * i, 3.0, 0.02 * i); };
  const Pose parked = planarPose(20, -5, 1.0);
  const int n = 6;
  w.ego.resize(n);
  w.object.resize(n);
  w.change.resize(n - 1);
  for (int i = 0; i < n; ++i) {
    w.ego[i] = toBlock(noisy(ego(i), rng, 0.3, 0.02));
    w.object[i] = toBlock(noisy(car(i), rng, 0.3, 0.02));
    if (i + 1 < n) w.change[i] = toBlock(noisy(car(i).inverse() * car(i + 1), rng, 0.1, 0.01));
  }
  w.landmark = toBlock(noisy(parked, rng, 0.3, 0.05));
  auto S = [](double t, double r) { return sqrtInformation((Vector6() << t, t, t, r, r, r).finished()); };
  auto loss = std::make_shared<ceres::CauchyLoss>(1.0);
  auto add = [&](ceres::CostFunction* c, std::shared_ptr<ceres::LossFunction> l, std::vector<double*> b) {
    w.factors.push_back(Factor{std::shared_ptr<ceres::CostFunction>(c), l, b});
  };
  add(MarginalizationPrior::CreatePosePrior(ego(0), S(0.01, 0.001)), nullptr, {w.ego[0].data()});
  for (int i = 0; i < n; ++i) {
    if (i > 0)
      add(OdometryFactor::Create(noisy(ego(i - 1).inverse() * ego(i), rng, 0.05, 0.005), S(0.05, 0.005)), nullptr,
          {w.ego[i - 1].data(), w.ego[i].data()});
    add(LandmarkObservationFactor::Create(noisy(ego(i).inverse() * parked, rng, 0.1, 0.02), S(0.15, 0.05)), loss,
        {w.ego[i].data(), w.landmark.data()});
    add(ObservationFactor::Create(noisy(ego(i).inverse() * car(i), rng, 0.1, 0.02), S(0.25, 0.1)), loss,
        {w.ego[i].data(), w.object[i].data()});
    if (i > 0)
      add(PoseChangeFactor::Create(S(0.02, 0.005)), nullptr,
          {w.object[i - 1].data(), w.object[i].data(), w.change[i - 1].data()});
    if (i > 1)
      add(ConstantVelocityFactor::Create(S(0.05, 0.01)), nullptr, {w.change[i - 2].data(), w.change[i - 1].data()});
  }
  for (int i = 0; i + 1 < n; ++i) w.separator.push_back(w.ego[i].data());
  w.separator.push_back(w.landmark.data());
  w.separator.push_back(w.ego[n - 1].data());
  std::vector<double*> chain;
  for (int i = 0; i < n; ++i) {
    chain.push_back(w.object[i].data());
    if (i + 1 < n) chain.push_back(w.change[i].data());
  }
  w.groups.push_back(chain);
}

}  // namespace

TEST(BackendWindowSolver, SameMinimumAndCovarianceAsCeres) {
  Window a, b;
  build(a, 21);
  build(b, 21);
  std::vector<const Factor*> factors;
  for (const Factor& f : a.factors) factors.push_back(&f);
  WindowSolver solver;
  WindowSolver::Options o;
  o.max_iterations = 100;
  o.function_tolerance = 1e-15;
  o.gradient_tolerance = 1e-14;
  o.parameter_tolerance = 1e-15;
  const auto summary = solver.solve(factors, a.separator, a.groups, {}, 2, o);
  WindowSolver whole_tail;  // every separator block in the tail
  whole_tail.solve(factors, a.separator, a.groups, {}, static_cast<int>(a.separator.size()), o);
  EXPECT_LT(summary.final_cost, summary.initial_cost);

  ceres::Problem::Options po;
  po.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(po);
  PoseManifold manifold;
  for (Vector7* v : {&b.landmark}) problem.AddParameterBlock(v->data(), 7, &manifold);
  for (auto* list : {&b.ego, &b.object, &b.change})
    for (Vector7& v : *list) problem.AddParameterBlock(v.data(), 7, &manifold);
  for (const Factor& f : b.factors) problem.AddResidualBlock(f.cost.get(), f.loss.get(), f.blocks);
  ceres::Solver::Options so;
  so.max_num_iterations = 100;
  so.function_tolerance = 1e-15;
  so.gradient_tolerance = 1e-14;
  so.parameter_tolerance = 1e-15;
  so.linear_solver_type = ceres::DENSE_QR;
  ceres::Solver::Summary cs;
  ceres::Solve(so, &problem, &cs);
  EXPECT_NEAR(summary.final_cost, cs.final_cost, 1e-9 * cs.final_cost);
  auto close = [](const Vector7& x, const Vector7& y) {
    return (fromBlock(x.data()).translation() - fromBlock(y.data()).translation()).norm() < 1e-6 &&
           logSO3(Eigen::Quaterniond(fromBlock(x.data()).linear().transpose() * fromBlock(y.data()).linear())).norm() < 1e-7;
  };
  for (size_t i = 0; i < a.ego.size(); ++i) EXPECT_TRUE(close(a.ego[i], b.ego[i])) << i;
  for (size_t i = 0; i < a.object.size(); ++i) EXPECT_TRUE(close(a.object[i], b.object[i])) << i;
  EXPECT_TRUE(close(a.landmark, b.landmark));

  // Marginal covariances: exact for the separator's tail (landmark, newest ego pose); for the
  // newest object pose, what the solver documents (given the separator, plus the tail's part).
  ceres::Covariance::Options co;
  co.algorithm_type = ceres::DENSE_SVD;
  ceres::Covariance covariance(co);
  const double* x_t = b.ego.back().data();
  const double* o_t = b.object.back().data();
  const double* o_prev = b.object[b.object.size() - 2].data();
  ASSERT_TRUE(covariance.Compute(
      {{x_t, x_t}, {b.landmark.data(), b.landmark.data()}, {o_t, o_t}, {o_prev, o_prev}, {o_prev, o_t}}, &problem));
  Matrix6 ego_ceres, landmark_ceres, object_ceres;
  covariance.GetCovarianceBlockInTangentSpace(x_t, x_t, ego_ceres.data());
  covariance.GetCovarianceBlockInTangentSpace(b.landmark.data(), b.landmark.data(), landmark_ceres.data());
  covariance.GetCovarianceBlockInTangentSpace(o_t, o_t, object_ceres.data());
  const auto ego = solver.covariance(a.ego.back().data());
  const auto landmark = solver.covariance(a.landmark.data());
  const auto object = solver.covariance(a.object.back().data());
  ASSERT_TRUE(ego && landmark && object);
  EXPECT_LT((*ego - ego_ceres).norm(), 1e-3 * ego_ceres.norm()) << *ego << "\n\n" << ego_ceres;
  EXPECT_LT((*landmark - landmark_ceres).norm(), 1e-3 * landmark_ceres.norm());
  // With only two blocks in the tail the object's leaves out its correlations through the other
  // ego poses: within 25 % of the exact marginal here. With all of them in the tail, exact.
  for (int i = 0; i < 6; ++i) EXPECT_NEAR((*object)(i, i) / object_ceres(i, i), 1.0, 0.25) << i;
  const auto object_exact = whole_tail.covariance(a.object.back().data());
  ASSERT_TRUE(object_exact.has_value());
  EXPECT_LT((*object_exact - object_ceres).norm(), 1e-3 * object_ceres.norm()) << *object_exact << "\n\n" << object_ceres;
  EXPECT_FALSE(solver.covariance(a.ego.front().data()).has_value());  // not in the tail

  // The joint covariance of two poses of the object (a velocity's, from their difference).
  Eigen::MatrixXd joint_ceres(12, 12);
  Matrix6 block;
  covariance.GetCovarianceBlockInTangentSpace(o_prev, o_prev, block.data());
  joint_ceres.topLeftCorner<6, 6>() = block.transpose();  // ceres writes row-major
  covariance.GetCovarianceBlockInTangentSpace(o_prev, o_t, block.data());
  joint_ceres.topRightCorner<6, 6>() = block.transpose();
  joint_ceres.bottomLeftCorner<6, 6>() = block;
  joint_ceres.bottomRightCorner<6, 6>() = object_ceres.transpose();
  const auto joint = whole_tail.jointCovariance({a.object[a.object.size() - 2].data(), a.object.back().data()});
  ASSERT_TRUE(joint.has_value());
  EXPECT_LT((*joint - joint_ceres).norm(), 1e-3 * joint_ceres.norm()) << *joint << "\n\n" << joint_ceres;
  EXPECT_FALSE(solver.jointCovariance({a.object.back().data(), a.ego.back().data()}).has_value());  // two groups
}
