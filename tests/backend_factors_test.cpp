// Every backend factor: its residual at a known configuration and its Jacobian against
// numeric differentiation in the PoseManifold's tangent space; the manifold itself; the
// marginalization prior; and the Marginalizer's linearization against Ceres' own.
#include <ceres/ceres.h>
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <memory>
#include <random>
#include <unordered_set>
#include <Eigen/Eigenvalues>

#include "backend/backend_config.hpp"
#include "backend/constant_acceleration_factor.hpp"
#include "backend/constant_velocity_factor.hpp"
#include "backend/dense_kernels.hpp"
#include "backend/landmark_observation_factor.hpp"
#include "backend/marginalization_prior.hpp"
#include "backend/marginalizer.hpp"
#include "backend/observation_factor.hpp"
#include "backend/odometry_factor.hpp"
#include "backend/pose_change_factor.hpp"
#include "backend/registration_factor.hpp"
#include "backend/face_heading_factor.hpp"
#include "backend/sight_speed_factor.hpp"
#include "backend/vehicle_motion_factor.hpp"
#include "backend/pose_manifold.hpp"
#include "backend_scene.hpp"

using namespace dlslot;
using namespace dlslot::backend;
using dlslot::backend::test::planarPose;

namespace {

Pose randomPose(std::mt19937& rng, double t_scale = 5.0, double r_scale = 1.0) {
  std::normal_distribution<double> n(0.0, 1.0);
  Vector6 d;
  for (int i = 0; i < 3; ++i) d[i] = t_scale * n(rng);
  for (int i = 3; i < 6; ++i) d[i] = r_scale * n(rng);
  return plus(Pose::Identity(), d);
}

Matrix6 randomSqrtInfo(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.5, 3.0), o(-0.3, 0.3);
  Matrix6 S = Matrix6::Zero();
  for (int r = 0; r < 6; ++r)
    for (int c = r; c < 6; ++c) S(r, c) = r == c ? u(rng) : o(rng);
  return S;
}

// Residual of `cost` at the given blocks.
Eigen::VectorXd residual(const ceres::CostFunction& cost, const std::vector<Vector7>& blocks) {
  std::vector<const double*> p;
  for (const auto& b : blocks) p.push_back(b.data());
  Eigen::VectorXd r(cost.num_residuals());
  EXPECT_TRUE(cost.Evaluate(p.data(), r.data(), nullptr));
  return r;
}

// Checks d residual / d tangent (analytic ambient Jacobian x PlusJacobian) against central
// differences through the manifold's Plus.
void expectJacobiansMatchNumeric(const ceres::CostFunction& cost, const std::vector<Vector7>& blocks,
                                 double tol = 1e-6) {
  const int m = cost.num_residuals();
  const int n = static_cast<int>(blocks.size());
  std::vector<const double*> p;
  for (const auto& b : blocks) p.push_back(b.data());
  std::vector<Eigen::Matrix<double, Eigen::Dynamic, 7, Eigen::RowMajor>> J(n);
  std::vector<double*> jp(n);
  for (int k = 0; k < n; ++k) {
    J[k].resize(m, 7);
    jp[k] = J[k].data();
  }
  Eigen::VectorXd r(m);
  ASSERT_TRUE(cost.Evaluate(p.data(), r.data(), jp.data()));
  PoseManifold manifold;
  const double h = 1e-6;
  for (int k = 0; k < n; ++k) {
    const Eigen::MatrixXd analytic = J[k] * PoseManifold::plusJacobian(blocks[k].data());
    Eigen::MatrixXd numeric(m, 6);
    for (int j = 0; j < 6; ++j) {
      Vector6 d = Vector6::Zero();
      d[j] = h;
      std::vector<Vector7> plus_b = blocks, minus_b = blocks;
      manifold.Plus(blocks[k].data(), d.data(), plus_b[k].data());
      d[j] = -h;
      manifold.Plus(blocks[k].data(), d.data(), minus_b[k].data());
      numeric.col(j) = (residual(cost, plus_b) - residual(cost, minus_b)) / (2 * h);
    }
    EXPECT_LT((analytic - numeric).norm(), tol * std::max(1.0, numeric.norm()))
        << "block " << k << "\nanalytic\n" << analytic << "\nnumeric\n" << numeric;
  }
}

Pose error(std::mt19937& rng) { return randomPose(rng, 0.3, 0.2); }

}  // namespace

TEST(BackendSe3, ExpLogRoundTripAndSmallAngles) {
  std::mt19937 rng(3);
  for (int i = 0; i < 50; ++i) {
    const Pose T = randomPose(rng, 1.0, 0.9);
    const Eigen::Vector3d phi = logSO3(Eigen::Quaterniond(T.linear()));
    EXPECT_TRUE(expSO3(phi).toRotationMatrix().isApprox(T.linear(), 1e-12));
  }
  const Eigen::Vector3d tiny(1e-12, -2e-12, 3e-12);
  EXPECT_TRUE(logSO3(expSO3(tiny)).isApprox(tiny, 1e-9));
  EXPECT_NEAR(logSO3(expSO3(Eigen::Vector3d(0, 0, 3.0))).z(), 3.0, 1e-12);
}

TEST(BackendPoseManifold, Invariants) {
  std::mt19937 rng(4);
  PoseManifold m;
  for (int i = 0; i < 20; ++i) {
    const Vector7 x = toBlock(randomPose(rng));
    Vector6 d;
    for (int j = 0; j < 6; ++j) d[j] = std::normal_distribution<double>(0, 0.4)(rng);
    Vector7 y, x0;
    const Vector6 zero = Vector6::Zero();
    m.Plus(x.data(), zero.data(), x0.data());
    EXPECT_TRUE(x0.isApprox(x, 1e-14));
    m.Plus(x.data(), d.data(), y.data());
    Vector6 back;
    m.Minus(y.data(), x.data(), back.data());
    EXPECT_TRUE(back.isApprox(d, 1e-10)) << back.transpose() << " vs " << d.transpose();
    // MinusJacobian is a left inverse of PlusJacobian.
    const Matrix6 I = PoseManifold::minusJacobian(x.data()) * PoseManifold::plusJacobian(x.data());
    EXPECT_TRUE(I.isApprox(Matrix6::Identity(), 1e-12));
    // PlusJacobian against central differences of Plus.
    Eigen::Matrix<double, 7, 6> numeric;
    for (int j = 0; j < 6; ++j) {
      Vector6 h = Vector6::Zero();
      h[j] = 1e-6;
      Vector7 a, b;
      m.Plus(x.data(), h.data(), a.data());
      h[j] = -1e-6;
      m.Plus(x.data(), h.data(), b.data());
      numeric.col(j) = (a - b) / 2e-6;
    }
    EXPECT_LT((numeric - Eigen::Matrix<double, 7, 6>(PoseManifold::plusJacobian(x.data()))).norm(), 1e-8);
    // MinusJacobian against central differences of Minus(., x) at x in ambient coordinates.
    Eigen::Matrix<double, 6, 7> numeric_minus;
    for (int j = 0; j < 7; ++j) {
      Vector7 a = x, b = x;
      a[j] += 1e-7;
      b[j] -= 1e-7;
      Vector6 da, db;
      m.Minus(a.data(), x.data(), da.data());
      m.Minus(b.data(), x.data(), db.data());
      numeric_minus.col(j) = (da - db) / 2e-7;
    }
    EXPECT_LT((numeric_minus - Eigen::Matrix<double, 6, 7>(PoseManifold::minusJacobian(x.data()))).norm(), 1e-6);
  }
}

TEST(BackendFactors, OdometryResidualAndJacobians) {
  std::mt19937 rng(5);
  for (int i = 0; i < 10; ++i) {
    const Pose Xp = randomPose(rng), Xc = randomPose(rng), E = error(rng);
    const Matrix6 S = randomSqrtInfo(rng);
    // T = (Xp^-1 Xc) E makes eq. 8's error exactly E.
    OdometryFactor f(Xp.inverse() * Xc * E, S);
    const std::vector<Vector7> blocks{toBlock(Xp), toBlock(Xc)};
    EXPECT_TRUE(residual(f, blocks).isApprox(S * logPose(E), 1e-9));
    expectJacobiansMatchNumeric(f, blocks);
  }
  OdometryFactor consistent(Pose::Identity(), Matrix6::Identity());
  const Pose X = planarPose(3, 4, 0.5);
  EXPECT_LT(residual(consistent, {toBlock(X), toBlock(X)}).norm(), 1e-12);
}

TEST(BackendFactors, ObservationAndLandmarkResidualAndJacobians) {
  std::mt19937 rng(6);
  for (int i = 0; i < 10; ++i) {
    const Pose X = randomPose(rng), o = randomPose(rng), E = error(rng);
    const Matrix6 S = randomSqrtInfo(rng);
    // b = X^-1 o E: eq. 9's error (X^-1 o)^-1 b is E.
    const Pose b = X.inverse() * o * E;
    ObservationFactor obs(b, S);
    LandmarkObservationFactor landmark(b, S);
    const std::vector<Vector7> blocks{toBlock(X), toBlock(o)};
    EXPECT_TRUE(residual(obs, blocks).isApprox(S * logPose(E), 1e-9));
    EXPECT_TRUE(residual(landmark, blocks).isApprox(S * logPose(E), 1e-9));
    expectJacobiansMatchNumeric(obs, blocks);
    expectJacobiansMatchNumeric(landmark, blocks);
  }
  // A box 10 m ahead, seen from the origin, of an object 10 m ahead: no error.
  ObservationFactor ahead(planarPose(10, 0, 0), Matrix6::Identity());
  EXPECT_LT(residual(ahead, {toBlock(Pose::Identity()), toBlock(planarPose(10, 0, 0))}).norm(), 1e-12);
  // The object 0.5 m to the left of where the box says: t_e = (0, -0.5, 0) in the object frame.
  const Eigen::VectorXd r = residual(ahead, {toBlock(Pose::Identity()), toBlock(planarPose(10, 0.5, 0))});
  EXPECT_NEAR(r[1], -0.5, 1e-12);
  EXPECT_NEAR(r.norm(), 0.5, 1e-12);
}

TEST(BackendFactors, PoseChangeResidualAndJacobians) {
  std::mt19937 rng(7);
  for (int i = 0; i < 10; ++i) {
    const Pose o1 = randomPose(rng), o2 = randomPose(rng), E = error(rng);
    const Matrix6 S = randomSqrtInfo(rng);
    // c = (o1^-1 o2) E: the corrected eq. 10, (o1^-1 o2)^-1 c, is E.
    const Pose c = o1.inverse() * o2 * E;
    PoseChangeFactor f(S);
    const std::vector<Vector7> blocks{toBlock(o1), toBlock(o2), toBlock(c)};
    EXPECT_TRUE(residual(f, blocks).isApprox(S * logPose(E), 1e-9));
    expectJacobiansMatchNumeric(f, blocks);
  }
  // eq. 2 holds exactly: no error.
  const Pose o1 = planarPose(1, 2, 0.3), o2 = planarPose(2, 2.5, 0.35);
  PoseChangeFactor f(Matrix6::Identity());
  EXPECT_LT(residual(f, {toBlock(o1), toBlock(o2), toBlock(o1.inverse() * o2)}).norm(), 1e-12);
}

TEST(BackendFactors, RegistrationResidualAndJacobians) {
  std::mt19937 rng(12);
  for (int i = 0; i < 10; ++i) {
    const Pose X1 = randomPose(rng), X2 = randomPose(rng), o1 = randomPose(rng), c = randomPose(rng, 1.0, 0.3),
               E = error(rng);
    const Matrix6 S = randomSqrtInfo(rng);
    // A_meas = (X2^-1 o1 c o1^-1 X1) E^-1: the factor's error is E.
    const Pose A = X2.inverse() * o1 * c * o1.inverse() * X1;
    RegistrationFactor f(A * E.inverse(), S);
    const std::vector<Vector7> blocks{toBlock(X1), toBlock(X2), toBlock(o1), toBlock(c)};
    EXPECT_TRUE(residual(f, blocks).isApprox(S * logPose(E), 1e-9));
    expectJacobiansMatchNumeric(f, blocks);
  }
}

TEST(BackendFactors, RegistrationMeasuresTheObjectAgainstTheSensorNotTheWorld) {
  // A car 10 m ahead moves 1.5 m along world x while the ego moves 2 m: its points, put into the
  // world with the ego poses of the time, register to M. Moving both ego poses together moves
  // nothing; moving the ego's motion by 0.1 m (another odometry) moves the car's by as much: the
  // measurement is the car against the sensor.
  const Pose X1 = planarPose(0, 0, 0), X2 = planarPose(2, 0, 0), o1 = planarPose(10, 0, 0),
             c = planarPose(1.5, 0, 0);
  const Pose M = o1 * c * o1.inverse();
  Matrix6 info = Matrix6::Identity() * 1e4;
  const RegistrationMeasurement rm = registrationMeasurement(M, info, X1, X2);
  RegistrationFactor f(rm.A_meas, rm.sqrt_info);
  EXPECT_LT(residual(f, {toBlock(X1), toBlock(X2), toBlock(o1), toBlock(c)}).norm(), 1e-9);
  const Pose shift = planarPose(3, -1, 0.2);
  EXPECT_LT(residual(f, {toBlock(shift * X1), toBlock(shift * X2), toBlock(shift * o1), toBlock(c)}).norm(), 1e-6);
  EXPECT_LT(residual(f, {toBlock(X1), toBlock(planarPose(2.1, 0, 0)), toBlock(o1), toBlock(planarPose(1.6, 0, 0))}).norm(),
            1e-6);
  EXPECT_NEAR(residual(f, {toBlock(X1), toBlock(planarPose(2.1, 0, 0)), toBlock(o1), toBlock(c)}).norm(), 0.1 * 100, 1e-6);
}

TEST(BackendFactors, SightSpeedResidualAndJacobians) {
  std::mt19937 rng(14);
  std::uniform_real_distribution<double> angle(-3.0, 3.0), dist(-0.5, 0.5);
  for (int i = 0; i < 10; ++i) {
    const Pose X1 = randomPose(rng), X2 = randomPose(rng), o1 = randomPose(rng), c = randomPose(rng, 1.0, 0.3);
    const double a = angle(rng), offset = dist(rng);
    const Eigen::Vector3d u(std::cos(a), std::sin(a), 0.0);
    const double d = u.dot(o1.linear() * c.translation() - (X2.translation() - X1.translation()));
    SightSpeedFactor f(u, d + offset, 0.1);
    const std::vector<Vector7> blocks{toBlock(X1), toBlock(X2), toBlock(o1), toBlock(c)};
    const Vector6 r = residual(f, blocks);
    EXPECT_NEAR(r[0], -offset / 0.1, 1e-9);
    EXPECT_LT(r.tail<5>().norm(), 1e-12);
    expectJacobiansMatchNumeric(f, blocks);
  }
}

TEST(BackendFactors, SightSpeedMeasuresTheFaceAgainstTheSensor) {
  // A car 40 m ahead drives at 5 m/s, the ego at 7 m/s, 0.1 s apart: its face comes 0.2 m nearer.
  // The ego and the car moved together by another 0.1 m change nothing; the car alone 0.1 m
  // faster along the line of sight is 0.1 m off, across it nothing.
  const Eigen::Vector3d u = Eigen::Vector3d::UnitX();
  const Pose X1 = planarPose(0, 0, 0), X2 = planarPose(0.7, 0, 0), o1 = planarPose(40, 0, 0.05);
  const Pose c = o1.inverse() * planarPose(40.5, 0, 0.05);
  SightSpeedFactor f(u, -0.2, 1.0);
  EXPECT_LT(residual(f, {toBlock(X1), toBlock(X2), toBlock(o1), toBlock(c)}).norm(), 1e-9);
  EXPECT_LT(residual(f, {toBlock(X1), toBlock(planarPose(0.8, 0, 0)), toBlock(o1),
                         toBlock(o1.inverse() * planarPose(40.6, 0, 0.05))}).norm(), 1e-9);
  EXPECT_NEAR(residual(f, {toBlock(X1), toBlock(X2), toBlock(o1), toBlock(o1.inverse() * planarPose(40.6, 0, 0.05))})[0],
              0.1, 1e-9);
  EXPECT_NEAR(residual(f, {toBlock(X1), toBlock(X2), toBlock(o1), toBlock(o1.inverse() * planarPose(40.5, 0.3, 0.05))})[0],
              0.0, 1e-9);
}

TEST(BackendFactors, FaceHeadingResidualAndJacobians) {
  std::mt19937 rng(15);
  std::uniform_real_distribution<double> offset(-0.2, 0.2);
  for (int i = 0; i < 10; ++i) {
    const Pose X = randomPose(rng), o = randomPose(rng);
    const Eigen::Vector3d h = X.linear().transpose() * o.linear().col(0);
    const double e = offset(rng);
    FaceHeadingFactor f(std::atan2(h.y(), h.x()) - e, 0.01);
    const std::vector<Vector7> blocks{toBlock(X), toBlock(o)};
    const Vector6 r = residual(f, blocks);
    EXPECT_NEAR(r[0], e / 0.01, 1e-9);
    EXPECT_LT(r.tail<5>().norm(), 1e-12);
    expectJacobiansMatchNumeric(f, blocks);
  }
  // Front and back are one heading to a face fit: a car turned round is no error.
  FaceHeadingFactor f(0.3, 0.01);
  EXPECT_NEAR(residual(f, {toBlock(planarPose(5, 1, 0.2)), toBlock(planarPose(20, 3, 0.5 + M_PI))})[0], 0.0, 1e-9);
}

TEST(BackendFactors, ConstantVelocityResidualAndJacobians) {
  std::mt19937 rng(8);
  for (int i = 0; i < 10; ++i) {
    const Pose c1 = randomPose(rng, 1.0, 0.3), E = error(rng);
    const Matrix6 S = randomSqrtInfo(rng);
    ConstantVelocityFactor f(S);
    const std::vector<Vector7> blocks{toBlock(c1), toBlock(c1 * E)};
    EXPECT_TRUE(residual(f, blocks).isApprox(S * logPose(E), 1e-9));
    expectJacobiansMatchNumeric(f, blocks);
  }
  // 1 m per frame, then 1.2 m per frame straight ahead: 0.2 m error along x.
  ConstantVelocityFactor f(Matrix6::Identity());
  const Eigen::VectorXd r = residual(f, {toBlock(planarPose(1, 0, 0)), toBlock(planarPose(1.2, 0, 0))});
  EXPECT_NEAR(r[0], 0.2, 1e-12);
  EXPECT_NEAR(r.norm(), 0.2, 1e-12);
}

TEST(BackendFactors, ConstantAccelerationResidualAndJacobians) {
  std::mt19937 rng(10);
  for (int i = 0; i < 10; ++i) {
    const std::vector<Vector7> blocks{toBlock(randomPose(rng, 1.0, 0.3)), toBlock(randomPose(rng, 1.0, 0.3)),
                                      toBlock(randomPose(rng, 1.0, 0.3))};
    ConstantAccelerationFactor f(randomSqrtInfo(rng));
    expectJacobiansMatchNumeric(f, blocks);
  }
  // Sigmas 0.01 m. 1.0, 1.1, 1.2 m per frame (constant acceleration), turning at a constant rate:
  // no cost. 1.0, 1.1, 1.3: the acceleration grew by 0.1 m per frame^2 -> 10 sigmas along x.
  const auto f = std::unique_ptr<ceres::CostFunction>(ConstantAccelerationFactor::Create(Eigen::Vector3d::Constant(0.01)));
  const auto& ca = static_cast<const ConstantAccelerationFactor&>(*f);
  EXPECT_LT(residual(ca, {toBlock(planarPose(1.0, 0, 0.05)), toBlock(planarPose(1.1, 0, 0.05)),
                          toBlock(planarPose(1.2, 0, 0.05))})
                .norm(),
            1e-12);
  const Eigen::VectorXd r =
      residual(ca, {toBlock(planarPose(1.0, 0, 0)), toBlock(planarPose(1.1, 0, 0)), toBlock(planarPose(1.3, 0, 0))});
  EXPECT_NEAR(r[0], 10.0, 1e-9);
  EXPECT_NEAR(r.norm(), 10.0, 1e-9);
}

TEST(BackendFactors, VehicleMotionResidualAndJacobians) {
  std::mt19937 rng(9);
  for (int i = 0; i < 10; ++i) {
    const Pose c = randomPose(rng, 1.0, 0.3);
    VehicleMotionFactor f(randomSqrtInfo(rng));
    expectJacobiansMatchNumeric(f, {toBlock(c)});
  }
  // Sigmas lateral 0.1 m, vertical 0.2 m, roll 0.01, pitch 0.02 rad. Forward motion and yaw cost
  // nothing; sideways and vertical motion, roll and pitch are whitened by their sigmas.
  const auto f = std::unique_ptr<ceres::CostFunction>(VehicleMotionFactor::Create(Eigen::Vector4d(0.1, 0.2, 0.01, 0.02)));
  const auto& vm = static_cast<const VehicleMotionFactor&>(*f);
  Pose forward_turning = planarPose(2.5, 0, 0.05);
  EXPECT_LT(residual(vm, {toBlock(forward_turning)}).norm(), 1e-12);
  const Eigen::VectorXd r = residual(vm, {toBlock(planarPose(2.5, 0.05, 0))});
  EXPECT_NEAR(r[1], 0.5, 1e-12);  // 0.05 m sideways / 0.1
  EXPECT_NEAR(r.norm(), 0.5, 1e-12);
  Pose climbing = Pose::Identity();
  climbing.translation() = Eigen::Vector3d(2.5, 0, 0.1);
  climbing.linear() = Eigen::AngleAxisd(0.002, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Eigen::VectorXd rc = residual(vm, {toBlock(climbing)});
  EXPECT_NEAR(rc[2], 0.5, 1e-12);  // 0.1 m up / 0.2
  EXPECT_NEAR(rc[4], 0.1, 1e-9);   // 0.002 rad of pitch / 0.02
}

TEST(BackendFactors, MarginalizationPriorResidualJacobianAndLinearization) {
  std::mt19937 rng(9);
  std::vector<Vector7> x_lin, x;
  for (int i = 0; i < 3; ++i) {
    const Pose p = randomPose(rng);
    x_lin.push_back(toBlock(p));
    x.push_back(toBlock(p * error(rng)));
  }
  const Eigen::MatrixXd J = Eigen::MatrixXd::Random(18, 18);
  const Eigen::VectorXd r0 = Eigen::VectorXd::Random(18);
  MarginalizationPrior prior(x_lin, J, r0);
  EXPECT_TRUE(residual(prior, x_lin).isApprox(r0, 1e-12));
  Eigen::VectorXd dx(18);
  for (int i = 0; i < 3; ++i) dx.segment<6>(6 * i) = minus(fromBlock(x[i].data()), fromBlock(x_lin[i].data()));
  EXPECT_TRUE(residual(prior, x).isApprox(r0 + J * dx, 1e-12));
  expectJacobiansMatchNumeric(prior, x, 1e-6);

  // linearize() gives Jx^T Jx and Jx^T r of the tangent Jacobian at x.
  std::vector<const double*> p;
  for (const auto& b : x) p.push_back(b.data());
  Eigen::MatrixXd H;
  Eigen::VectorXd g;
  prior.linearize(p.data(), H, g);
  Eigen::MatrixXd Jx(18, 18);
  for (int i = 0; i < 3; ++i) Jx.middleCols<6>(6 * i) = J.middleCols<6>(6 * i) * minusJacobianAt(fromBlock(x[i].data()), fromBlock(x_lin[i].data()));
  EXPECT_TRUE(H.isApprox(Jx.transpose() * Jx, 1e-10));
  EXPECT_TRUE(g.isApprox(Jx.transpose() * residual(prior, x), 1e-10));
}

// With nothing leaving, the Marginalizer's prior is the Gauss-Newton model of its factors:
// J*^T J* and J*^T r* must equal what Ceres itself computes (tangent Jacobian, robust loss).
TEST(BackendMarginalizer, LinearizationMatchesCeres) {
  std::mt19937 rng(10);
  std::vector<Vector7> blocks;
  for (int i = 0; i < 4; ++i) blocks.push_back(toBlock(randomPose(rng)));
  std::vector<Factor> factors;
  auto loss = std::make_shared<ceres::CauchyLoss>(1.0);
  factors.push_back({std::shared_ptr<ceres::CostFunction>(OdometryFactor::Create(error(rng), randomSqrtInfo(rng))), nullptr,
                     {blocks[0].data(), blocks[1].data()}});
  factors.push_back({std::shared_ptr<ceres::CostFunction>(ObservationFactor::Create(error(rng), randomSqrtInfo(rng))), loss,
                     {blocks[1].data(), blocks[2].data()}});
  factors.push_back({std::shared_ptr<ceres::CostFunction>(PoseChangeFactor::Create(randomSqrtInfo(rng))), nullptr,
                     {blocks[0].data(), blocks[2].data(), blocks[3].data()}});
  Marginalizer marginalizer;
  std::vector<const Factor*> all;
  for (const Factor& f : factors) all.push_back(&f);
  const std::optional<Factor> prior = marginalizer.marginalize(all, {}, {});
  ASSERT_TRUE(prior.has_value());

  ceres::Problem::Options po;
  po.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(po);
  PoseManifold manifold;
  std::vector<double*> order = prior->blocks;
  for (double* b : order) problem.AddParameterBlock(b, 7, &manifold);
  for (const Factor& f : factors) problem.AddResidualBlock(f.cost.get(), f.loss.get(), f.blocks);
  ceres::Problem::EvaluateOptions eo;
  eo.parameter_blocks = order;
  std::vector<double> r;
  ceres::CRSMatrix crs;
  double cost = 0;
  problem.Evaluate(eo, &cost, &r, nullptr, &crs);
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int row = 0; row < crs.num_rows; ++row)
    for (int k = crs.rows[row]; k < crs.rows[row + 1]; ++k) J(row, crs.cols[k]) = crs.values[k];
  const Eigen::VectorXd rv = Eigen::Map<Eigen::VectorXd>(r.data(), r.size());

  const auto* mp = dynamic_cast<const MarginalizationPrior*>(prior->cost.get());
  ASSERT_NE(mp, nullptr);
  Eigen::MatrixXd H;
  Eigen::VectorXd g;
  mp->linearize(prior->blocks.data(), H, g);
  EXPECT_TRUE(H.isApprox(J.transpose() * J, 1e-9)) << H - J.transpose() * J;
  EXPECT_TRUE(g.isApprox(J.transpose() * rv, 1e-9));
}

// Marginalizing a block is the Schur complement of the linearized system.
TEST(BackendMarginalizer, SchurComplementOfTheLinearizedSystem) {
  std::mt19937 rng(11);
  std::vector<Vector7> blocks;
  for (int i = 0; i < 3; ++i) blocks.push_back(toBlock(randomPose(rng)));
  std::vector<Factor> factors;
  factors.push_back({std::shared_ptr<ceres::CostFunction>(MarginalizationPrior::CreatePosePrior(
                         plus(fromBlock(blocks[0].data()), Vector6::Constant(0.01)), randomSqrtInfo(rng))),
                     nullptr, {blocks[0].data()}});
  factors.push_back({std::shared_ptr<ceres::CostFunction>(OdometryFactor::Create(error(rng), randomSqrtInfo(rng))), nullptr,
                     {blocks[0].data(), blocks[1].data()}});
  factors.push_back({std::shared_ptr<ceres::CostFunction>(OdometryFactor::Create(error(rng), randomSqrtInfo(rng))), nullptr,
                     {blocks[0].data(), blocks[2].data()}});
  std::vector<const Factor*> all;
  for (const Factor& f : factors) all.push_back(&f);
  Marginalizer marginalizer;
  const auto full = marginalizer.marginalize(all, {}, {});
  const auto reduced = marginalizer.marginalize(all, {blocks[0].data()}, {});
  ASSERT_TRUE(full && reduced);
  EXPECT_EQ(marginalizer.lastStats().leaving_dim, 6);
  EXPECT_EQ(marginalizer.lastStats().kept_dim, 12);
  Eigen::MatrixXd H, Hr;
  Eigen::VectorXd g, gr;
  dynamic_cast<const MarginalizationPrior&>(*full->cost).linearize(full->blocks.data(), H, g);
  dynamic_cast<const MarginalizationPrior&>(*reduced->cost).linearize(reduced->blocks.data(), Hr, gr);
  // full->blocks is {b0, b1, b2}; reduced->blocks is {b1, b2}.
  ASSERT_EQ(full->blocks[0], blocks[0].data());
  const Eigen::MatrixXd Hmm = H.topLeftCorner(6, 6), Hmr = H.topRightCorner(6, 12);
  const Eigen::MatrixXd expected_H = H.bottomRightCorner(12, 12) - Hmr.transpose() * Hmm.inverse() * Hmr;
  const Eigen::VectorXd expected_g = g.tail(12) - Hmr.transpose() * Hmm.inverse() * g.head(6);
  EXPECT_TRUE(Hr.isApprox(expected_H, 1e-8));
  EXPECT_TRUE(gr.isApprox(expected_g, 1e-8));
}

// The Schur complement of the full linearization (H, g over `full`'s blocks) onto the blocks
// `reduced` keeps, in `reduced`'s block order; H_mm^-1 is the pseudo-inverse (eigenvalues below
// 1e-8 of the largest dropped), which is the inverse when H_mm is definite.
std::pair<Eigen::MatrixXd, Eigen::VectorXd> expectedSchur(const Factor& full, const Factor& reduced,
                                                          const std::unordered_set<const double*>& leaving) {
  Eigen::MatrixXd H;
  Eigen::VectorXd g;
  dynamic_cast<const MarginalizationPrior&>(*full.cost).linearize(full.blocks.data(), H, g);
  std::vector<int> m, r;
  for (int k = 0; k < static_cast<int>(full.blocks.size()); ++k)
    for (int d = 0; d < 6; ++d) (leaving.count(full.blocks[k]) ? m : r).push_back(6 * k + d);
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(H(m, m));
  const Eigen::VectorXd lambda = es.eigenvalues();
  const Eigen::VectorXd inv = (lambda.array() > 1e-8 * lambda.maxCoeff()).select(lambda.cwiseInverse(), 0.0);
  const Eigen::MatrixXd Hmm_inv = es.eigenvectors() * inv.asDiagonal() * es.eigenvectors().transpose();
  const Eigen::MatrixXd Hmr = H(m, r);
  const Eigen::MatrixXd expected_H = H(r, r) - Hmr.transpose() * Hmm_inv * Hmr;
  const Eigen::VectorXd expected_g = g(r) - Hmr.transpose() * Hmm_inv * g(m);
  std::vector<int> perm;  // reduced block k -> its rows in expected_*
  for (double* b : reduced.blocks) {
    int pos = 0;
    for (double* a : full.blocks)
      if (!leaving.count(a)) {
        if (a == b) break;
        ++pos;
      }
    for (int d = 0; d < 6; ++d) perm.push_back(6 * pos + d);
  }
  return {expected_H(perm, perm), expected_g(perm)};
}

// Several leaving blocks, each kept block coupled to a different one (a staircase in L^-1 H_mr,
// which the Marginalizer exploits panel by panel: 6 kept blocks make two panels), under a
// dense prior: still exactly the Schur complement.
TEST(BackendMarginalizer, StaircaseSchurComplementUnderADensePrior) {
  std::mt19937 rng(12);
  const int n = 6;
  std::vector<Vector7> blocks;
  for (int i = 0; i < 2 * n; ++i) blocks.push_back(toBlock(randomPose(rng)));
  std::vector<Factor> factors;
  auto add = [&](ceres::CostFunction* c, std::vector<int> b) {
    std::vector<double*> ptrs;
    for (int i : b) ptrs.push_back(blocks[i].data());
    factors.push_back({std::shared_ptr<ceres::CostFunction>(c), nullptr, ptrs});
  };
  // A dense prior over blocks 0..n-1 (they leave), then chains i -> i + n.
  std::vector<Vector7> x_lin(blocks.begin(), blocks.begin() + n);
  const Eigen::MatrixXd J = Eigen::MatrixXd::Random(6 * n, 6 * n) + 5.0 * Eigen::MatrixXd::Identity(6 * n, 6 * n);
  std::vector<double*> prior_blocks;
  std::unordered_set<const double*> leaving;
  for (int i = 0; i < n; ++i) {
    prior_blocks.push_back(blocks[i].data());
    leaving.insert(blocks[i].data());
  }
  factors.push_back({std::make_shared<MarginalizationPrior>(x_lin, J, Eigen::VectorXd::Random(6 * n)), nullptr,
                     prior_blocks});
  for (int i = 0; i < n; ++i) add(OdometryFactor::Create(error(rng), randomSqrtInfo(rng)), {i, i + n});
  add(PoseChangeFactor::Create(randomSqrtInfo(rng)), {2, n + 2, n + 1});
  std::vector<const Factor*> all;
  for (const Factor& f : factors) all.push_back(&f);
  Marginalizer marginalizer;
  const auto full = marginalizer.marginalize(all, {}, {});
  const auto reduced = marginalizer.marginalize(all, leaving, {});
  ASSERT_TRUE(full && reduced);
  EXPECT_EQ(marginalizer.lastStats().leaving_dim, 6 * n);
  EXPECT_EQ(marginalizer.lastStats().kept_dim, 6 * n);
  Eigen::MatrixXd Hr;
  Eigen::VectorXd gr;
  dynamic_cast<const MarginalizationPrior&>(*reduced->cost).linearize(reduced->blocks.data(), Hr, gr);
  const auto [expected_H, expected_g] = expectedSchur(*full, *reduced, leaving);
  EXPECT_TRUE(Hr.isApprox(expected_H, 1e-8));
  EXPECT_TRUE(gr.isApprox(expected_g, 1e-8));
}

// A leaving block with a direction no factor constrains (its only factor's information has a
// zero row): H_mm is singular and the Marginalizer falls back to the pseudo-inverse, which
// passes on what the other directions say and nothing about the free one.
TEST(BackendMarginalizer, SingularLeavingBlockUsesThePseudoInverse) {
  std::mt19937 rng(13);
  std::vector<Vector7> blocks;
  for (int i = 0; i < 3; ++i) blocks.push_back(toBlock(randomPose(rng)));
  Matrix6 S = randomSqrtInfo(rng);
  S.row(4).setZero();
  std::vector<Factor> factors;
  factors.push_back({std::shared_ptr<ceres::CostFunction>(PoseChangeFactor::Create(S)), nullptr,
                     {blocks[0].data(), blocks[1].data(), blocks[2].data()}});
  factors.push_back({std::shared_ptr<ceres::CostFunction>(OdometryFactor::Create(error(rng), randomSqrtInfo(rng))),
                     nullptr, {blocks[1].data(), blocks[2].data()}});
  factors.push_back({std::shared_ptr<ceres::CostFunction>(MarginalizationPrior::CreatePosePrior(
                         plus(fromBlock(blocks[1].data()), Vector6::Constant(0.02)), randomSqrtInfo(rng))),
                     nullptr, {blocks[1].data()}});
  std::vector<const Factor*> all;
  for (const Factor& f : factors) all.push_back(&f);
  Marginalizer marginalizer;
  const auto full = marginalizer.marginalize(all, {}, {});
  const std::unordered_set<const double*> leaving{blocks[0].data()};
  const auto reduced = marginalizer.marginalize(all, leaving, {});
  ASSERT_TRUE(full && reduced);
  Eigen::MatrixXd Hmm, Hr;
  Eigen::VectorXd g, gr;
  dynamic_cast<const MarginalizationPrior&>(*full->cost).linearize(full->blocks.data(), Hmm, g);
  ASSERT_EQ(full->blocks[0], blocks[0].data());
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(Eigen::MatrixXd(Hmm.topLeftCorner(6, 6)));
  ASSERT_LT(es.eigenvalues()(0), 1e-9 * es.eigenvalues()(5));  // singular indeed
  dynamic_cast<const MarginalizationPrior&>(*reduced->cost).linearize(reduced->blocks.data(), Hr, gr);
  const auto [expected_H, expected_g] = expectedSchur(*full, *reduced, leaving);
  EXPECT_TRUE(Hr.isApprox(expected_H, 1e-6));
  EXPECT_TRUE(gr.isApprox(expected_g, 1e-6));
  EXPECT_TRUE(Hr.allFinite() && gr.allFinite());
}

// The CPU-specific kernels against Eigen's own algorithms.
TEST(BackendDenseKernels, MatchEigen) {
  const int n = 37, m = 5;
  const Eigen::MatrixXd R = Eigen::MatrixXd::Random(n, n);
  const Eigen::MatrixXd A = R * R.transpose() + n * Eigen::MatrixXd::Identity(n, n);
  Eigen::MatrixXd L = A;
  ASSERT_TRUE(dense::cholesky(L));
  const Eigen::MatrixXd L_ref = A.llt().matrixL();
  EXPECT_TRUE(Eigen::MatrixXd(L.triangularView<Eigen::Lower>()).isApprox(L_ref, 1e-12));
  Eigen::MatrixXd not_definite = -A;
  EXPECT_FALSE(dense::cholesky(not_definite));
  const Eigen::MatrixXd B = Eigen::MatrixXd::Random(n, m);
  Eigen::MatrixXd X = B;
  dense::solveLower(L, X);
  EXPECT_TRUE((L_ref * X).isApprox(B, 1e-12));
  X = B;
  dense::solveLowerTransposed(L, X);
  EXPECT_TRUE((L_ref.transpose() * X).isApprox(B, 1e-12));
  const Eigen::MatrixXd Y = Eigen::MatrixXd::Random(9, n);
  Eigen::MatrixXd S = A;
  dense::subtractGramRows(dense::RowMatrix(Y), S);
  const Eigen::MatrixXd expected = A - Y.transpose() * Y;
  EXPECT_TRUE(Eigen::MatrixXd(S.triangularView<Eigen::Lower>()).isApprox(Eigen::MatrixXd(expected.triangularView<Eigen::Lower>()), 1e-12));
  const Eigen::MatrixXd Z = Eigen::MatrixXd::Random(9, m);
  Eigen::MatrixXd C = B;
  dense::subtractProductTN(Y, Z, C);
  EXPECT_TRUE(C.isApprox(B - Y.transpose() * Z, 1e-12));
}

// The band kernels against a dense factorization of the same matrix: 7 blocks of 6, bandwidth
// 2, damping on the diagonal; the staircase solve touches only the columns it is given.
TEST(BackendDenseKernels, BandMatchesDense) {
  const int m = 7, w = 2, n = 6 * m;
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < m; ++i)
    for (int j = std::max(0, i - w); j <= i; ++j) A.block<6, 6>(6 * i, 6 * j) = Eigen::MatrixXd::Random(6, 6);
  A = (A * A.transpose()).eval();  // banded: products of lower-banded factors keep 2w blocks
  Eigen::MatrixXd band_full = Eigen::MatrixXd::Zero(n, n);
  const int bw = 2 * w;
  std::vector<Matrix6> H(m * (bw + 1), Matrix6::Zero());
  for (int i = 0; i < m; ++i)
    for (int d = 0; d <= std::min(i, bw); ++d) H[i * (bw + 1) + d] = A.block<6, 6>(6 * i, 6 * (i - d));
  const Eigen::VectorXd damping = Eigen::VectorXd::Constant(n, 0.5);
  std::vector<Matrix6> L, L_inv;
  ASSERT_TRUE(dense::bandCholesky(H, m, bw, damping, L, L_inv));
  Eigen::MatrixXd damped = A;
  damped.diagonal() += damping;
  const Eigen::MatrixXd L_ref = damped.llt().matrixL();
  for (int i = 0; i < m; ++i)
    for (int d = 0; d <= std::min(i, bw); ++d)
      EXPECT_TRUE(L[i * (bw + 1) + d].isApprox(L_ref.block<6, 6>(6 * i, 6 * (i - d)), 1e-10)) << i << " " << d;
  // A staircase right-hand side: block row i is non-zero in its first widths[i] columns.
  const std::vector<int> widths = {2, 2, 3, 3, 5, 5, 5};
  dense::RowMatrix Bm = dense::RowMatrix::Zero(n, 5);
  for (int i = 0; i < m; ++i) Bm.block(6 * i, 0, 6, widths[i]).setRandom();
  const Eigen::MatrixXd B0 = Bm;
  dense::bandSolveLower(L, L_inv, bw, Bm, &widths);
  EXPECT_TRUE((L_ref * Eigen::MatrixXd(Bm)).isApprox(B0, 1e-10));
  dense::bandSolveLowerTransposed(L, L_inv, bw, Bm);
  EXPECT_TRUE((damped * Eigen::MatrixXd(Bm)).isApprox(B0, 1e-10));
  dense::RowMatrix v = dense::RowMatrix::Random(n, 1);  // a vector takes a path of its own
  const Eigen::VectorXd v0 = v;
  dense::bandSolveLower(L, L_inv, bw, v);
  EXPECT_TRUE((L_ref * Eigen::VectorXd(v)).isApprox(v0, 1e-10));
  dense::bandSolveLowerTransposed(L, L_inv, bw, v);
  EXPECT_TRUE((damped * Eigen::VectorXd(v)).isApprox(v0, 1e-10));
  Matrix6 not_definite = -Matrix6::Identity();
  std::vector<Matrix6> H_bad(m * (bw + 1), Matrix6::Zero());
  for (int i = 0; i < m; ++i) H_bad[i * (bw + 1)] = i == 3 ? not_definite : Matrix6::Identity();
  EXPECT_FALSE(dense::bandCholesky(H_bad, m, bw, Eigen::VectorXd::Zero(n), L, L_inv));
}

TEST(BackendConfig, ShippedConfigReadsAndSqrtInformation) {
  ConfigSection root = loadConfig(std::string(DLSLOT_SOURCE_DIR) + "/config/dlslot.yaml");
  ConfigSection section = root.section("backend");
  const BackendConfig c = BackendConfig::read(section);
  section.skip("join_timeout_s");
  EXPECT_NO_THROW(section.finish());
  EXPECT_EQ(c.mode, Mode::kSlot);
  EXPECT_EQ(c.window_size, 10);
  const Matrix6 S = sqrtInformation(c.odometry_sigma);
  EXPECT_NEAR(S(0, 0), 1.0 / c.odometry_sigma[0], 1e-12);
  EXPECT_EQ(parseMode("two-stage"), Mode::kTwoStage);
  EXPECT_THROW(parseMode("joint"), std::invalid_argument);
  // A bad value under `key` is a config error naming the file and the key.
  auto expectRefused = [](const std::string& key, const char* bad) {
    YAML::Node node = YAML::LoadFile(std::string(DLSLOT_SOURCE_DIR) + "/config/dlslot.yaml")["backend"];
    node[key] = YAML::Load(bad);
    ConfigSection edited(node, "cfg.yaml", "backend");
    try {
      BackendConfig::read(edited);
      ADD_FAILURE() << key << ": " << bad;
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find("cfg.yaml: backend." + key), std::string::npos) << e.what();
    }
  };
  // A sigma list of the wrong length or with a non-positive entry.
  for (const char* bad : {"[0.005, 0.005]", "[0.005, 0.0, 0.005]"}) expectRefused("constant_acceleration_sigma", bad);
  // The odometry covariance scale: two factors, translation and rotation.
  EXPECT_EQ(c.odometry_covariance_scale, Eigen::Vector2d(5.0, 5.0));
  for (const char* bad : {"20", "[5, 20, 1]", "[5, 0]"}) expectRefused("odometry_covariance_scale", bad);
  // The odometry factor's consistency test: a probability strictly inside (0, 1), a support >= 1.
  EXPECT_TRUE(c.odometry_check.enabled);
  EXPECT_EQ(c.odometry_check.probability, 0.9999);
  for (const char* bad : {"0", "1", "1.5"}) expectRefused("odometry_check_probability", bad);
  expectRefused("odometry_check_min_support", "0");
  // A class's heading sigma replaces the box's rz when larger, for moving objects and landmarks.
  EXPECT_EQ(c.boxSigma("Cyclist", true)[5], 0.57);
  EXPECT_EQ(c.boxSigma("Cyclist", false)[5], 0.57);
  EXPECT_EQ(c.boxSigma("Car", true), c.observation_sigma);
  EXPECT_EQ(c.boxSigma("Car", false), c.landmark_sigma);
  for (const char* bad : {"{Cyclist: 0}", "{Cyclist: fast}", "[0.3]"}) expectRefused("heading_sigma_by_type", bad);
  EXPECT_EQ(c.walker_line_span_s, 2.0);
  expectRefused("walker_line_span_s", "-1");
  EXPECT_EQ(c.walker_rms_speed, 1.5);
  for (const char* bad : {"-1", "slow"}) expectRefused("walker_rms_speed", bad);
  EXPECT_EQ(c.side_azimuth_step_deg, 0.18);
  for (const char* bad : {"-0.1", "10", "fine"}) expectRefused("side_azimuth_step_deg", bad);
  EXPECT_EQ(c.side_length_tolerance, 0.5);
  expectRefused("side_length_tolerance", "0");
  EXPECT_EQ(c.switch_min_sigmas, 3.0);
  expectRefused("switch_min_sigmas", "-1");
  EXPECT_EQ(c.vehicle_acceleration, 1.0);
  for (const char* bad : {"-1", "fast"}) expectRefused("vehicle_acceleration", bad);
  EXPECT_EQ(c.vehicle_lateral_jerk, 1.0);
  for (const char* bad : {"-0.5", "sharp"}) expectRefused("vehicle_lateral_jerk", bad);
  EXPECT_EQ(c.line_of_sight_series, 6);
  for (const char* bad : {"-1", "11", "six"}) expectRefused("line_of_sight_series", bad);  // window_size 10
  EXPECT_EQ(c.line_of_sight_tolerance, 0.15);
  expectRefused("line_of_sight_tolerance", "0");
  EXPECT_TRUE(c.registration_missed_vehicles);
  expectRefused("registration_missed_vehicles", "sometimes");
}
