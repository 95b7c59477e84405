// The SlidingWindow estimator on synthetic scenes with known ground truth: sliding window +
// marginalization against the full batch solution, robustness, gaps, missing odometry, a
// parked car pulling out, and the modes.
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>

#include "backend/sliding_window.hpp"
#include "backend_scene.hpp"
#include "object_scan.hpp"

using namespace dlslot;
using namespace dlslot::backend;
using namespace dlslot::backend::test;

namespace {

std::vector<BackendOutput> run(SlidingWindow& window, const std::vector<BackendInput>& inputs) {
  std::vector<BackendOutput> out;
  for (const BackendInput& in : inputs) out.push_back(window.process(in));
  return out;
}

BackendConfig exactConfig(int window_size) {
  BackendConfig c;
  c.window_size = window_size;
  c.observation_loss = "none";
  c.max_iterations = 50;
  c.function_tolerance = 1e-16;
  c.gradient_tolerance = 1e-16;
  c.parameter_tolerance = 1e-16;
  c.compute_covariance = false;
  // The constant-acceleration factors are dropped, not marginalized, when the window slides
  // (sliding_window.cpp): switched off here so the window must equal the batch exactly.
  c.constant_acceleration_sigma.setConstant(1e6);
  return c;
}

double translationError(const Pose& a, const Pose& b) { return (a.translation() - b.translation()).norm(); }
double rotationError(const Pose& a, const Pose& b) { return logSO3(Eigen::Quaterniond(a.linear().transpose() * b.linear())).norm(); }

// Ego driving along x at 10 m/s; parked cars on the x axis it passes (seen 1..30 m ahead),
// two cars ahead on the same axis at 8 and 12 m/s, the second one unseen for frames 15-17.
// All rotations are the identity and every noise is along x, so (by symmetry) the optimum
// keeps them so and the problem is exactly linear in the x coordinates: Gaussian elimination
// (marginalization) must then reproduce the batch solution exactly.
SimScene linearScene() {
  SimScene s;
  s.ego = constantTwist(Pose::Identity(), 10.0, 0.0);
  s.odometry_noise << 0.05, 0, 0, 0, 0, 0;
  s.box_noise << 0.05, 0, 0;
  for (int k = 0; k < 20; ++k) {
    SimObject o;
    o.id = k;
    const double x = 15.0 + 12.0 * k;
    o.pose = [x](double) { return planarPose(x, 0, 0); };
    o.visible = [x](int f) {
      const double ahead = x - 10.0 * 0.1 * f;
      return ahead > 1.0 && ahead < 30.0;
    };
    s.objects.push_back(o);
  }
  SimObject a, b;
  a.id = 100;
  a.pose = constantTwist(planarPose(10, 0, 0), 8.0, 0.0);
  b.id = 101;
  b.pose = constantTwist(planarPose(5, 0, 0), 12.0, 0.0);
  b.visible = [](int f) { return f < 15 || f > 17; };
  s.objects.push_back(a);
  s.objects.push_back(b);
  return s;
}

}  // namespace

TEST(BackendSlidingWindow, LinearGaussianChainEqualsBatch) {
  const SimScene scene = linearScene();
  const std::vector<BackendInput> inputs = scene.generate(40);
  SlidingWindow window(exactConfig(6)), batch(exactConfig(1000));
  const auto sw = run(window, inputs);
  const auto full = run(batch, inputs);
  // The newest pose of every frame is the batch solution over all frames so far.
  double worst = 0;
  for (size_t t = 0; t < inputs.size(); ++t) worst = std::max(worst, translationError(sw[t].ego_pose, full[t].ego_pose));
  EXPECT_LT(worst, 1e-6);
  EXPECT_GT(window.priorDimension(), 0);
  // Everything still in the window equals the batch estimate of the same state.
  for (int f : window.windowFrames()) {
    EXPECT_LT(translationError(*window.egoPose(f), *batch.egoPose(f)), 1e-6) << "frame " << f;
    EXPECT_LT(rotationError(*window.egoPose(f), *batch.egoPose(f)), 1e-9) << "frame " << f;
    for (int id : {100, 101, 3, 4}) {
      const auto a = window.objectPose(id, f), b = batch.objectPose(id, f);
      ASSERT_EQ(a.has_value(), b.has_value()) << "track " << id << " frame " << f;
      if (a) {
        EXPECT_LT(translationError(*a, *b), 1e-6) << "track " << id << " frame " << f;
      }
    }
  }
  EXPECT_EQ(window.trackModel(100), SlidingWindow::TrackModel::kDynamic);
  EXPECT_EQ(window.trackModel(101), SlidingWindow::TrackModel::kDynamic);
  EXPECT_EQ(window.trackModel(4), SlidingWindow::TrackModel::kStatic);
  EXPECT_EQ(window.trackModel(0), SlidingWindow::TrackModel::kNotInGraph);  // passed and marginalized
}

// With the constant-acceleration factors on, the window drops them at its edge instead of
// marginalizing them: no longer the batch solution, but close to it.
TEST(BackendSlidingWindow, DroppedAccelerationFactorsStayCloseToBatch) {
  const std::vector<BackendInput> inputs = linearScene().generate(40);
  BackendConfig c = exactConfig(6), b = exactConfig(1000);
  c.constant_acceleration_sigma = b.constant_acceleration_sigma = BackendConfig().constant_acceleration_sigma;
  c.marginalize_acceleration = false;
  SlidingWindow window(c), batch(b);
  const auto sw = run(window, inputs);
  const auto full = run(batch, inputs);
  double worst = 0;
  for (size_t t = 0; t < inputs.size(); ++t) worst = std::max(worst, translationError(sw[t].ego_pose, full[t].ego_pose));
  EXPECT_GT(worst, 1e-6);  // the approximation is there ...
  EXPECT_LT(worst, 0.005);  // ... and small next to 0.05 m of odometry noise a frame
  for (int f : window.windowFrames())
    for (int id : {100, 101})
      if (const auto a = window.objectPose(id, f)) {
        EXPECT_LT(translationError(*a, *batch.objectPose(id, f)), 0.05) << "track " << id << " frame " << f;
      }
}

// Marginalized with the leaving pose change instead, the constant-acceleration factors keep the
// window much closer to the batch solution (the prior's second pose change has no rotation
// information: the Marginalizer factorizes without those directions).
TEST(BackendSlidingWindow, MarginalizedAccelerationFactorsStayCloserToBatch) {
  const std::vector<BackendInput> inputs = linearScene().generate(40);
  BackendConfig b = exactConfig(1000);
  b.constant_acceleration_sigma = BackendConfig().constant_acceleration_sigma;
  SlidingWindow batch(b);
  const auto full = run(batch, inputs);
  double worst[2] = {0, 0};
  for (const bool marginalize : {false, true}) {
    BackendConfig c = exactConfig(6);
    c.constant_acceleration_sigma = b.constant_acceleration_sigma;
    c.marginalize_acceleration = marginalize;
    SlidingWindow window(c);
    const auto sw = run(window, inputs);
    for (size_t t = 0; t < inputs.size(); ++t)
      worst[marginalize] = std::max(worst[marginalize], translationError(sw[t].ego_pose, full[t].ego_pose));
  }
  std::printf("newest ego pose vs batch: worst %.2e m with the acceleration factors dropped, %.2e m marginalized\n",
              worst[0], worst[1]);
  EXPECT_LT(worst[1], 0.5 * worst[0]);  // measured 1.0e-3 and 3.3e-4 m
}

namespace {

// A turning ego (10 m/s, 0.1 rad/s) on a street with parked cars on both sides and three
// moving cars, 3D odometry noise and box noise: the general nonlinear case.
SimScene streetScene() {
  SimScene s;
  s.ego = constantTwist(Pose::Identity(), 10.0, 0.1);
  s.odometry_noise << 0.02, 0.02, 0.01, 0.002, 0.002, 0.003;
  s.box_noise << 0.1, 0.1, 0.05;
  s.yaw_noise = 0.03;
  const auto ego = s.ego;
  auto inRange = [ego](std::function<Pose(double)> pose, double range) {
    return [ego, pose, range](int f) { return translationError(ego(0.1 * f), pose(0.1 * f)) < range; };
  };
  for (int k = 0; k < 16; ++k) {
    SimObject o;
    o.id = k;
    const Pose along = ego(0.25 * k + 0.5);
    const Pose parked = along * planarPose(0, k % 2 ? 7.0 : -7.0, 0.1 * k);
    o.pose = [parked](double) { return parked; };
    o.visible = inRange(o.pose, 30.0);
    s.objects.push_back(o);
  }
  const double speeds[] = {11.0, 9.0, -8.0};
  const double lateral[] = {3.5, -3.5, 7.0};
  for (int k = 0; k < 3; ++k) {
    SimObject o;
    o.id = 100 + k;
    const Pose start = planarPose(12.0 + 10 * k, lateral[k], speeds[k] < 0 ? M_PI : 0.0);
    o.pose = constantTwist(start, std::abs(speeds[k]), speeds[k] < 0 ? -0.05 : 0.1);
    o.visible = inRange(o.pose, 40.0);
    s.objects.push_back(o);
  }
  return s;
}

// The backend's settings for the street scene, whose odometry reports its true covariance.
BackendConfig streetConfig() {
  BackendConfig c;
  c.compute_covariance = false;
  c.odometry_covariance_scale = Eigen::Vector2d(1.0, 1.0);
  return c;
}

}  // namespace

TEST(BackendSlidingWindow, NonlinearCaseStaysCloseToBatch) {
  SimScene scene = streetScene();
  const std::vector<BackendInput> inputs = scene.generate(40);
  const BackendConfig c = streetConfig();
  BackendConfig b = c;
  b.window_size = 1000;
  SlidingWindow window(c), batch(b);
  const auto sw = run(window, inputs);
  const auto full = run(batch, inputs);
  double worst_t = 0, worst_r = 0, sw_err = 0, odo_err = 0;
  for (size_t t = 0; t < inputs.size(); ++t) {
    worst_t = std::max(worst_t, translationError(sw[t].ego_pose, full[t].ego_pose));
    worst_r = std::max(worst_r, rotationError(sw[t].ego_pose, full[t].ego_pose));
    sw_err += translationError(sw[t].ego_pose, scene.egoTruth(t)) / inputs.size();
    odo_err += translationError(inputs[t].odometry->pose, scene.egoTruth(t)) / inputs.size();
  }
  std::printf("nonlinear: newest pose vs batch: worst %.2e m, %.2e rad; mean error to truth %.3f m (odometry %.3f m)\n",
              worst_t, worst_r, sw_err, odo_err);
  EXPECT_LT(worst_t, 0.02);
  EXPECT_LT(worst_r, 0.002);
  EXPECT_LT(sw_err, odo_err);
}

TEST(BackendSlidingWindow, FarOffSpuriousDetectionDoesNotPullTheEgoPose) {
  const SimScene scene = streetScene();
  const std::vector<BackendInput> clean = scene.generate(30);
  std::vector<BackendInput> spurious = clean;
  // At frame 25 the detection given to a parked car's track is 8 m off (a false positive the
  // tracker associated).
  int victim = -1;
  for (ObservationInput& o : spurious[25].observations)
    if (o.track_id < 100 && o.initialized) {
      o.box.center += Eigen::Vector3d(3.0, 7.4, 0.0);
      victim = o.track_id;
      break;
    }
  ASSERT_GE(victim, 0);
  auto shiftAt25 = [&](const std::string& loss) {
    BackendConfig c = streetConfig();
    c.observation_loss = loss;
    SlidingWindow a(c), b(c);
    const std::vector<BackendInput> clean_head(clean.begin(), clean.begin() + 27);
    const std::vector<BackendInput> spurious_head(spurious.begin(), spurious.begin() + 27);
    const auto ra = run(a, clean_head), rb = run(b, spurious_head);
    // With the robust loss, one detection is not evidence enough to call the parked car
    // moving (without it, the landmark is dragged and its next observations look far off).
    if (loss == "cauchy") {
      EXPECT_EQ(b.trackModel(victim), SlidingWindow::TrackModel::kStatic);
    }
    return translationError(ra[25].ego_pose, rb[25].ego_pose);
  };
  const double robust = shiftAt25("cauchy"), plain = shiftAt25("none");
  std::printf("8 m spurious detection moves the ego pose by %.4f m (cauchy) / %.4f m (no robust loss)\n", robust, plain);
  EXPECT_LT(robust, 0.01);
  EXPECT_GT(plain, 3 * robust);
}

TEST(BackendSlidingWindow, ObjectDisappearsAndReappears) {
  SimScene scene;
  scene.ego = constantTwist(Pose::Identity(), 10.0, 0.0);
  scene.odometry_noise << 0.01, 0.01, 0.005, 0.001, 0.001, 0.001;
  scene.box_noise << 0.05, 0.05, 0.02;
  SimObject short_gap, long_gap;
  short_gap.id = 1;
  short_gap.pose = constantTwist(planarPose(15, 3.5, 0), 12.0, 0.0);
  short_gap.visible = [](int f) { return f < 20 || f > 24; };  // unseen for 5 frames
  long_gap.id = 2;
  long_gap.pose = constantTwist(planarPose(10, -3.5, 0), 9.0, 0.0);
  long_gap.visible = [](int f) { return f < 10 || f > 30; };  // unseen for longer than the window
  scene.objects = {short_gap, long_gap};
  const auto inputs = scene.generate(45);
  BackendConfig c;
  c.compute_covariance = false;
  SlidingWindow window(c);
  for (int f = 0; f <= 25; ++f) {
    const BackendOutput out = window.process(inputs[f]);
    if (f == 22) {
      // Both unseen now; the short gap's track is still in the window, predicted ahead.
      ASSERT_EQ(window.trackModel(1), SlidingWindow::TrackModel::kDynamic);
      ASSERT_EQ(window.trackModel(2), SlidingWindow::TrackModel::kNotInGraph);  // marginalized
      bool found = false;
      for (const TrackEstimate& e : out.tracks)
        if (e.id == 1) {
          found = true;
          EXPECT_EQ(e.last_seen_frame, 19);
          EXPECT_LT(translationError(e.pose, scene.objectTruth(1, 22)), 0.5);
        }
      EXPECT_TRUE(found);
    }
  }
  // Reappeared at 25: the gap is bridged by per-frame poses at constant velocity.
  EXPECT_EQ(window.trackModel(1), SlidingWindow::TrackModel::kDynamic);
  for (int f = 20; f <= 24; ++f) {
    const auto o = window.objectPose(1, f);
    ASSERT_TRUE(o.has_value()) << f;
    // Relative to the ego (the world position also carries the odometry's drift).
    const Pose relative = window.egoPose(f)->inverse() * *o;
    const Pose relative_true = scene.egoTruth(f).inverse() * scene.objectTruth(1, f);
    EXPECT_LT(translationError(relative, relative_true), 0.2) << f;
  }
  BackendOutput out;
  for (int f = 26; f < 45; ++f) out = window.process(inputs[f]);
  for (const TrackEstimate& e : out.tracks) {
    const Eigen::Vector3d v_true = e.id == 1 ? Eigen::Vector3d(12, 0, 0) : Eigen::Vector3d(9, 0, 0);
    EXPECT_TRUE(e.dynamic) << e.id;
    EXPECT_LT((e.velocity - v_true).norm(), 0.5) << e.id << ": " << e.velocity.transpose();
    if (e.id == 2) {
      EXPECT_EQ(e.age, 44);  // the age counts from the first sighting
    }
  }
  EXPECT_EQ(out.tracks.size(), 2u);
}

TEST(BackendSlidingWindow, FrameWithoutOdometry) {
  SimScene scene = streetScene();
  scene.frames_without_odometry = {20};
  const auto inputs = scene.generate(30);
  for (Mode mode : {Mode::kSlot, Mode::kOdometryOnly}) {
    BackendConfig c = streetConfig();
    c.mode = mode;
    SlidingWindow window(c);
    const auto out = run(window, inputs);
    EXPECT_TRUE(out[20].odometry_missing);
    EXPECT_FALSE(out[21].odometry_missing);
    // The motion into frame 20 is predicted at constant velocity (and, in slot mode, corrected
    // by the landmarks): close to the true motion.
    const Pose motion = out[19].ego_pose.inverse() * out[20].ego_pose;
    const Pose motion_true = scene.egoTruth(19).inverse() * scene.egoTruth(20);
    EXPECT_LT(translationError(motion, motion_true), 0.1) << toString(mode);
    EXPECT_LT(rotationError(motion, motion_true), 0.01) << toString(mode);
    if (mode == Mode::kSlot) {
      EXPECT_LT(translationError(out[20].ego_pose, scene.egoTruth(20)), 0.3);
      EXPECT_LT(translationError(out[29].ego_pose, scene.egoTruth(29)), 0.3);
    }
  }
}

TEST(BackendSlidingWindow, FallenBackOdometryKeepsAStoppedEgoInPlace) {
  // The ego stands still among braking cars (moving objects cannot tell the ego's own velocity).
  // From frame 10 the odometry falls back: it publishes its prediction (standing still) flagged
  // not ok, with its wide placeholder covariance (1 m, 5 deg). The backend must use its own
  // degraded sigmas, not that placeholder, or the cars' constant-velocity chains drag the ego.
  SimScene scene;
  for (int k = 0; k < 4; ++k) {
    SimObject car;
    car.id = k;
    const double y = -6.0 + 4.0 * k, v0 = 12.0 + k;
    car.pose = [y, v0](double t) { return planarPose(-20.0 + v0 * t - 1.5 * t * t, y, 0.0); };
    car.dynamic_guess = true;
    scene.objects.push_back(car);
  }
  scene.box_noise = Eigen::Vector3d(0.1, 0.1, 0.05);
  std::vector<BackendInput> inputs = scene.generate(40);
  Matrix6 placeholder = Matrix6::Zero();
  placeholder.diagonal() << 1, 1, 1, 0.0076, 0.0076, 0.0076;
  for (int f = 10; f < 40; ++f) {
    inputs[f].odometry->ok = false;
    inputs[f].odometry->covariance = placeholder;
  }
  BackendConfig c = streetConfig();
  c.odometry_covariance_scale = Eigen::Vector2d(5.0, 20.0);
  SlidingWindow window(c);
  const auto out = run(window, inputs);
  double worst = 0;
  for (int f = 10; f < 40; ++f) worst = std::max(worst, out[f].ego_pose.translation().norm());
  std::printf("stopped ego, odometry fallen back for 30 frames: drift up to %.2f m\n", worst);
  EXPECT_LT(worst, 2.5);  // 16 m when the placeholder covariance was used
}

TEST(BackendSlidingWindow, MovingVehiclesCorrectAnOdometryPitchDrift) {
  // The odometry pitches down by 0.5 mrad a frame (A-LOAM's drift on scans with biased beam
  // angles); cars move straight on flat ground, oncoming and alongside. Eq. 11 alone accepts
  // objects that seem to climb at a constant rate; the vehicle motion prior does not, so the
  // joint estimate keeps the pitch closer to the truth (0.0185 against 0.029 rad here).
  SimScene scene;
  scene.ego = constantTwist(Pose::Identity(), 10.0, 0.0);
  for (int k = 0; k < 6; ++k) {
    SimObject car;
    car.id = k;
    const bool oncoming = k % 2 == 0;
    car.pose = constantTwist(planarPose(oncoming ? 60.0 + 25 * k : 5.0 + 6 * k, oncoming ? 4.0 : -3.5, oncoming ? M_PI : 0),
                             oncoming ? 12.0 : 10.0, 0.0);
    car.dynamic_guess = true;
    scene.objects.push_back(car);
  }
  scene.box_noise = Eigen::Vector3d(0.05, 0.05, 0.03);
  std::vector<BackendInput> inputs = scene.generate(60);
  Pose bias = Pose::Identity();
  bias.linear() = Eigen::AngleAxisd(-5e-4, Eigen::Vector3d::UnitY()).toRotationMatrix();
  for (size_t f = 1; f < inputs.size(); ++f) {
    inputs[f].odometry->delta = inputs[f].odometry->delta * bias;
    inputs[f].odometry->pose = inputs[f - 1].odometry->pose * inputs[f].odometry->delta;
    inputs[f].odometry->covariance = Matrix6::Identity() * 1e-6;
  }
  BackendConfig with = streetConfig(), without = streetConfig();
  without.vehicle_types.clear();
  SlidingWindow a(with), b(without);
  const auto out_with = run(a, inputs), out_without = run(b, inputs);
  const int last = 59;
  const double odometry = rotationError(inputs[last].odometry->pose, scene.egoTruth(last));
  const double joint = rotationError(out_with[last].ego_pose, scene.egoTruth(last));
  const double no_prior = rotationError(out_without[last].ego_pose, scene.egoTruth(last));
  std::printf("pitch drift after 60 frames: odometry %.4f rad, joint without the vehicle prior %.4f, with it %.4f\n",
              odometry, no_prior, joint);
  EXPECT_LT(joint, 0.7 * odometry);
  EXPECT_LT(joint, 0.7 * no_prior);
}

TEST(BackendSlidingWindow, CoastingTrackKeepsItsVelocityWhileItsChainLeavesTheWindow) {
  // A car seen for 20 frames, then not: until its last observation leaves the window it is
  // output (coasting) with the velocity its chain gave, not a fit of the one or two sightings
  // left in the window (or none at all: zero).
  SimScene scene;
  scene.ego = constantTwist(Pose::Identity(), 8.0, 0.0);
  SimObject car;
  car.id = 1;
  car.pose = constantTwist(planarPose(10, -3.5, 0), 12.0, 0.0);
  car.visible = [](int f) { return f < 20; };
  scene.objects = {car};
  scene.box_noise = Eigen::Vector3d(0.1, 0.1, 0.05);
  SlidingWindow window(streetConfig());
  int coasting = 0;
  for (const BackendOutput& out : run(window, scene.generate(35)))
    for (const TrackEstimate& e : out.tracks) {
      if (e.status != TrackStatus::Coasting) continue;
      ++coasting;
      EXPECT_NEAR(e.velocity.head<2>().norm(), 12.0, 1.0) << "frame " << out.frame;
    }
  EXPECT_GE(coasting, 8);
}

TEST(BackendSlidingWindow, ACarSeenTurnedRoundIsPublishedHeadingWhereItGoes) {
  // Every box of this car points backwards (a detector's heading turned by pi) while it drives
  // along +x at 12 m/s: the published heading is its direction of travel once it is moving.
  SimScene scene;
  scene.ego = constantTwist(Pose::Identity(), 8.0, 0.0);
  SimObject car;
  car.id = 1;
  car.pose = constantTwist(planarPose(10, -3.5, M_PI), -12.0, 0.0);  // facing -x, moving +x
  scene.objects = {car};
  scene.box_noise = Eigen::Vector3d(0.1, 0.1, 0.05);
  SlidingWindow window(streetConfig());
  int checked = 0;
  for (const BackendOutput& out : run(window, scene.generate(30)))
    for (const TrackEstimate& e : out.tracks) {
      if (!e.dynamic || e.velocity.head<2>().norm() < 6.0) continue;
      EXPECT_GT(e.velocity.x(), 6.0) << "frame " << out.frame;
      EXPECT_NEAR(std::abs(wrapAngle(yawOf(e.pose.linear()))), 0.0, 0.1) << "frame " << out.frame;
      ++checked;
    }
  EXPECT_GE(checked, 15);
}

TEST(BackendSlidingWindow, ASlowCarBornFromATurnedBoxIsPublishedFacingWhereItsDetectionsSay) {
  // A car creeping along +x at 2 m/s (too slow for its motion to tell its front), facing +x. Its
  // first box comes turned by pi, so its track heads -x; every later box but one (frame 12, turned
  // too) faces +x. Its detections' majority decides: published facing +x from its first output.
  SimScene scene;
  scene.ego = constantTwist(Pose::Identity(), 5.0, 0.0);
  SimObject car;
  car.id = 1;
  car.pose = constantTwist(planarPose(15, -3.5, 0.0), 2.0, 0.0);
  scene.objects = {car};
  scene.box_noise = Eigen::Vector3d(0.05, 0.05, 0.02);
  scene.yaw_noise = 0.02;
  auto inputs = scene.generate(30);
  for (int f : {0, 12}) inputs[f].observations.at(0).box.yaw += M_PI;
  SlidingWindow window(streetConfig());
  int checked = 0;
  for (const BackendOutput& out : run(window, inputs))
    for (const TrackEstimate& e : out.tracks) {
      EXPECT_NEAR(wrapAngle(yawOf(e.pose.linear())), 0.0, 0.15) << "frame " << out.frame;
      ++checked;
    }
  EXPECT_GE(checked, 25);
}

TEST(BackendSlidingWindow, ParkedCarPullsOutTurnsDynamic) {
  SimScene scene;
  scene.ego = constantTwist(Pose::Identity(), 5.0, 0.0);
  scene.odometry_noise << 0.01, 0.01, 0.005, 0.001, 0.001, 0.001;
  scene.box_noise << 0.05, 0.05, 0.02;
  scene.yaw_noise = 0.01;
  SimObject car;
  car.id = 7;
  // Parked 30 m ahead on the right; from t = 2 s it accelerates at 2.5 m/s^2 along the road.
  car.pose = [](double t) {
    const double s = t < 2.0 ? 0.0 : 1.25 * (t - 2.0) * (t - 2.0);
    return planarPose(30.0 + s, -4.0, 0.0);
  };
  SimObject other;  // a parked car further on keeps the ego pose honest
  other.id = 8;
  other.pose = [](double) { return planarPose(25.0, 5.0, 0.3); };
  scene.objects = {car, other};
  const auto inputs = scene.generate(45);
  BackendConfig c;
  c.compute_covariance = false;
  SlidingWindow window(c);
  int switched_at = -1;
  BackendOutput out;
  for (int f = 0; f < 45; ++f) {
    out = window.process(inputs[f]);
    if (f == 18) {
      EXPECT_EQ(window.trackModel(7), SlidingWindow::TrackModel::kStatic);
    }
    if (out.static_to_dynamic > 0) switched_at = f;
  }
  std::printf("parked car pulled out at frame 20, turned dynamic at frame %d\n", switched_at);
  EXPECT_EQ(window.trackModel(7), SlidingWindow::TrackModel::kDynamic);
  EXPECT_GT(switched_at, 20);
  EXPECT_LT(switched_at, 32);
  EXPECT_EQ(window.trackModel(8), SlidingWindow::TrackModel::kStatic);
  for (const TrackEstimate& e : out.tracks) {
    if (e.id != 7) continue;
    EXPECT_TRUE(e.dynamic);
    EXPECT_NEAR(e.velocity.x(), 2.5 * (4.4 - 2.0), 1.0);
  }
  EXPECT_LT(translationError(out.ego_pose, scene.egoTruth(44)), 0.2);
}

// Eq. 12's membership: O_init gets observation factors, O_aso (>= 2 frames) pose changes,
// O_cons (>= 3) constant velocity.
TEST(BackendSlidingWindow, FactorMembershipFollowsEquation12) {
  SimScene scene;
  scene.ego = constantTwist(Pose::Identity(), 10.0, 0.0);
  SimObject car;
  car.id = 1;
  car.pose = constantTwist(planarPose(10, 3, 0), 15.0, 0.0);
  scene.objects = {car};
  scene.init_after = 3;
  const auto inputs = scene.generate(5);
  BackendConfig c;
  c.compute_covariance = false;
  SlidingWindow window(c);
  std::vector<int> factors;
  for (const auto& in : inputs) factors.push_back(window.process(in).stats.num_factors);
  // gauge prior | + odometry | + odometry, observation (initialized at its 3rd sighting) |
  // + odometry, observation, pose change, vehicle motion | + odometry, observation, pose change,
  // vehicle motion, constant velocity
  EXPECT_EQ(factors, (std::vector<int>{1, 2, 4, 8, 13}));
  EXPECT_EQ(window.trackModel(1), SlidingWindow::TrackModel::kDynamic);
  // A pedestrian's pose changes get no vehicle motion prior.
  scene.objects[0].type = "Pedestrian";
  SlidingWindow walker(c);
  factors.clear();
  for (const auto& in : scene.generate(5)) factors.push_back(walker.process(in).stats.num_factors);
  EXPECT_EQ(factors, (std::vector<int>{1, 2, 4, 7, 11}));
}

namespace {

// A pedestrian (id 5) at `speed` m/s crossing 20 m ahead of an ego driving at 8 m/s, its boxes
// `box_noise` m (and `yaw_noise` rad) off.
SimScene walkerScene(double speed, double box_noise, double yaw_noise, unsigned seed = 1) {
  SimScene scene;
  scene.seed = seed;
  scene.ego = constantTwist(Pose::Identity(), 8.0, 0.0);
  scene.box_noise << box_noise, box_noise, 0.03;
  scene.yaw_noise = yaw_noise;
  SimObject walker;
  walker.id = 5;
  walker.type = "Pedestrian";
  walker.size = Eigen::Vector3d(0.8, 0.6, 1.7);
  walker.pose = constantTwist(planarPose(20, -6, M_PI / 2), speed, 0.0);
  scene.objects = {walker};
  return scene;
}

// The worst velocity error of a walker (1.4 m/s) the tracker now and then gives a stray box
// `aside` m to its side (a wrong association in a crowd), from frame 12 on.
double walkerWithStrayBoxes(double aside) {
  SimScene scene = walkerScene(1.4, 0.08, 0.05);
  const SimObject walker = scene.objects[0];
  const std::set<int> stray{14, 19, 23, 26, 31, 35};
  scene.objects[0].visible = [stray](int f) { return !stray.count(f); };
  for (int f : stray) {
    const Pose b = scene.egoTruth(f).inverse() * walker.pose(scene.time(f)) * planarPose(0, aside, 0);
    ObservationInput obs;
    obs.track_id = 5;
    obs.initialized = true;
    obs.box.type = "Pedestrian";
    obs.box.id = 5;
    obs.box.size = walker.size;
    obs.box.center = b.translation();
    obs.box.yaw = yawOf(b.linear()) + 1.3;  // its own heading, not the walker's
    scene.extra.insert({f, obs});
  }
  BackendConfig c;
  c.compute_covariance = false;
  SlidingWindow window(c);
  const auto out = run(window, scene.generate(40));
  const Eigen::Vector3d truth(0.0, 1.4, 0.0);  // world = the first scan's frame
  double worst = 0;
  for (int t = 12; t < 40; ++t)
    for (const TrackEstimate& e : out[t].tracks)
      if (e.id == 5) worst = std::max(worst, (e.velocity - truth).head<2>().norm());
  return worst;
}

}  // namespace

// A pedestrian's velocity is the line through its boxes in the window among outliers: a stray box
// 1.2 m aside, too near to be left out, bends it by up to 1.02 m/s (its chain's newest pose change,
// as before: 1.82); one 4 m aside is left out.
TEST(BackendSlidingWindow, APedestriansVelocitySurvivesStrayBoxes) {
  const double near = walkerWithStrayBoxes(1.2), far = walkerWithStrayBoxes(4.0);
  std::printf("walker with stray boxes: worst velocity error %.2f m/s (1.2 m aside), %.2f m/s (4 m aside)\n", near, far);
  EXPECT_LT(near, 1.2);
  EXPECT_LT(far, 0.6);
}

namespace {

// The RMS velocity error (m/s, frames 25-59) of a walker at 1.4 m/s whose boxes jitter by 0.15 m,
// its line spanning `span` s (0: the window's boxes alone).
double walkerVelocityError(double span) {
  const SimScene scene = walkerScene(1.4, 0.15, 0.3);
  BackendConfig c;
  c.compute_covariance = false;
  c.walker_line_span_s = span;
  SlidingWindow window(c);
  const auto out = run(window, scene.generate(60));
  const Eigen::Vector3d truth(0.0, 1.4, 0.0);
  double sum = 0;
  int n = 0;
  for (int t = 25; t < 60; ++t)
    for (const TrackEstimate& e : out[t].tracks)
      if (e.id == 5) sum += (e.velocity - truth).head<2>().squaredNorm(), ++n;
  return n ? std::sqrt(sum / n) : 1e9;
}

}  // namespace

// A walker's line keeps its boxes for walker_line_span_s after they leave the window: over 2 s
// instead of the window's 1 s the slope of 20 jittering boxes is 2.8x steadier than that of 10.
TEST(BackendSlidingWindow, AWalkersLineOutlastsTheWindow) {
  const double window_only = walkerVelocityError(0.0), two_seconds = walkerVelocityError(2.0);
  std::printf("walker: velocity RMSE %.3f m/s (window), %.3f m/s (2 s line)\n", window_only, two_seconds);
  EXPECT_LT(two_seconds, 0.6 * window_only);
}

namespace {

// Every estimate of a pedestrian at `speed` m/s (boxes 0.15 m off, the tracker guessing it still)
// over 10 seeds of 40 frames, its line over 2 s; a still one judged again at every frame at
// `switch_sigmas` (0: never).
void forEachWalkerEstimate(double speed, double switch_sigmas, bool covariance,
                           const std::function<void(const TrackEstimate&)>& f) {
  for (unsigned seed = 1; seed <= 10; ++seed) {
    const SimScene scene = walkerScene(speed, 0.15, 0.3, seed);
    BackendConfig c;
    c.compute_covariance = covariance;
    c.walker_line_span_s = 2.0;
    c.switch_min_sigmas = switch_sigmas;
    SlidingWindow window(c);
    for (const BackendOutput& out : run(window, scene.generate(40)))
      for (const TrackEstimate& e : out.tracks)
        if (e.id == 5) f(e);
  }
}

// Frames the pedestrian is published still after its first output.
int framesPublishedStill(double speed, double switch_sigmas) {
  int still = 0;
  forEachWalkerEstimate(speed, switch_sigmas, false, [&](const TrackEstimate& e) { still += !e.dynamic; });
  return still;
}

}  // namespace

// A walker its first 3-4 boxes could not tell from a standing pedestrian is judged again at every
// frame as its line grows: before, it waited to be switch_distance from its landmark, which
// follows its boxes. A standing pedestrian stays still at 3 sigmas (at 2, now and then not).
TEST(BackendSlidingWindow, AWalkerStartedStillIsJudgedAgainAsItsLineGrows) {
  const int before = framesPublishedStill(1.2, 0.0), walking = framesPublishedStill(1.2, 3.0);
  const int standing = framesPublishedStill(0.0, 3.0), standing_at_2 = framesPublishedStill(0.0, 2.0);
  std::printf("pedestrian published still (of 380 frames): walking at 1.2 m/s %d (not judged again: %d), standing "
              "%d (at 2 sigmas: %d)\n", walking, before, standing, standing_at_2);
  EXPECT_LT(walking, 0.7 * before);
  EXPECT_EQ(standing, 380);
  EXPECT_LT(standing_at_2, 380);
}

// A still track is published with zero velocity and a covariance of that zero about the truth:
// its window's evidence of motion, spread and mean. A walker at 1.2 m/s whose first boxes cannot
// tell it from standing (published still in some frames) keeps its true velocity inside the 95 %
// ellipse there; a standing one's sigma stays near its boxes' line's (0.15 m box noise).
TEST(BackendSlidingWindow, AStillTracksVelocityCovarianceCoversWhatItMayBeDoing) {
  for (const double speed : {1.2, 0.0}) {
    int still = 0, inside = 0;
    double variance = 0;
    forEachWalkerEstimate(speed, 3.0, true, [&](const TrackEstimate& e) {
      if (e.dynamic) return;
      const Eigen::Matrix2d C = e.velocity_covariance.topLeftCorner<2, 2>();
      EXPECT_GT(C.determinant(), 0.0);
      EXPECT_EQ(e.velocity.norm(), 0.0);
      const Eigen::Vector2d truth(0.0, speed);  // the walker heads along +y
      ++still;
      inside += C.determinant() > 0 && truth.dot(C.inverse() * truth) <= 5.991;  // chi-square, 2 dof, 95 %
      variance += 0.5 * C.trace();
    });
    std::printf("pedestrian at %.1f m/s published still in %d frames: %d inside the 95 %% ellipse, sigma %.2f m/s\n",
                speed, still, inside, std::sqrt(variance / still));
    ASSERT_GT(still, speed > 0 ? 10 : 300);
    EXPECT_GE(inside, 0.95 * still);
    if (speed == 0.0) {
      EXPECT_LT(std::sqrt(variance / still), 0.5);
    }
  }
}

namespace {

// The mean velocity error (m/s, frames 15-39) of a cyclist at 4.5 m/s tracked on a pedestrian
// detector's boxes, whose heading is 0.4 rad off its own, plus 0.3 rad of noise (PointRCNN's
// pedestrian boxes on KITTI's cyclists: median 0.35 rad off), missed in every fifth frame, its
// boxes' heading believed to `heading_sigma` (rad; 0: observation_sigma's 0.1).
double cyclistOnPedestrianBoxes(double heading_sigma, unsigned seed) {
  SimScene scene;
  scene.seed = seed;
  scene.ego = constantTwist(Pose::Identity(), 8.0, 0.0);
  scene.box_noise << 0.08, 0.08, 0.03;
  scene.yaw_noise = 0.3;
  SimObject cyclist;
  cyclist.id = 4;
  cyclist.type = "Cyclist";
  cyclist.size = Eigen::Vector3d(0.9, 0.7, 1.7);
  const double heading = 0.3, speed = 4.5;
  const auto path = constantTwist(planarPose(12, -4, heading), speed, 0.0);
  cyclist.pose = [path](double t) { return path(t) * planarPose(0, 0, 0.4); };
  cyclist.visible = [](int f) { return f % 5 != 4; };
  scene.objects = {cyclist};
  BackendConfig c;
  c.compute_covariance = false;
  c.observation_sigma[5] = 0.1;
  if (heading_sigma > 0) c.heading_sigma_by_type["Cyclist"] = heading_sigma;
  SlidingWindow window(c);
  const auto out = run(window, scene.generate(40));
  const Eigen::Vector3d truth(speed * std::cos(heading), speed * std::sin(heading), 0.0);
  double sum = 0;
  int n = 0;
  for (int t = 15; t < 40; ++t)
    for (const TrackEstimate& e : out[t].tracks)
      if (e.id == 4) sum += (e.velocity - truth).head<2>().norm(), ++n;
  return n ? sum / n : 1e9;
}

}  // namespace

// A cyclist moves along its heading (the vehicle-motion factor), so a heading believed from its
// boxes turns its velocity with them; believed as well as the detector knows it, its motion
// decides (the real slice's cyclist: 1.2 -> 0.26 m/s). With so weak a heading, a box is turned
// round only against the track's newest pose: extrapolated by a young chain's yaw rate, it turned
// right boxes round and the chain spun.
TEST(BackendSlidingWindow, ACyclistsVelocityFollowsItsMotionNotAPedestrianBoxsHeading) {
  double believed = 0, as_measured = 0;
  for (unsigned seed = 1; seed <= 10; ++seed) {
    const double a = cyclistOnPedestrianBoxes(0.0, seed), b = cyclistOnPedestrianBoxes(0.57, seed);
    std::printf("seed %u: cyclist on pedestrian boxes, mean velocity error %.2f m/s (heading sigma 0.1), %.2f (0.57)\n",
                seed, a, b);
    believed = std::max(believed, a);
    as_measured = std::max(as_measured, b);
  }
  EXPECT_GT(believed, 0.25);
  EXPECT_LT(as_measured, 0.2);
}

TEST(BackendSlidingWindow, TwoStageAndOdometryOnlyKeepTheOdometryPoses) {
  const SimScene scene = streetScene();
  const auto inputs = scene.generate(25);
  for (Mode mode : {Mode::kTwoStage, Mode::kOdometryOnly}) {
    BackendConfig c = streetConfig();
    c.mode = mode;
    SlidingWindow window(c);
    const auto out = run(window, inputs);
    for (size_t t = 0; t < inputs.size(); ++t)
      EXPECT_LT(translationError(out[t].ego_pose, inputs[t].odometry->pose), 1e-12) << toString(mode);
    if (mode == Mode::kOdometryOnly) {
      EXPECT_TRUE(out.back().tracks.empty());
    } else {
      EXPECT_FALSE(out.back().tracks.empty());
      for (const TrackEstimate& e : out.back().tracks) {
        if (e.id == 100) {
          EXPECT_NEAR(e.velocity.norm(), 11.0, 1.0);
        }
      }
    }
  }
}

TEST(BackendSlidingWindow, CovariancesAreReported) {
  const SimScene scene = streetScene();
  const auto inputs = scene.generate(15);
  BackendConfig c = streetConfig();
  c.compute_covariance = true;
  SlidingWindow window(c);
  const auto out = run(window, inputs);
  const BackendOutput& last = out.back();
  EXPECT_GT(last.ego_covariance(0, 0), 0.0);
  EXPECT_TRUE(last.ego_covariance.isApprox(last.ego_covariance.transpose(), 1e-9));
  int with_cov = 0;
  for (const TrackEstimate& e : last.tracks) with_cov += e.covariance(0, 0) > 0.0;
  EXPECT_GT(with_cov, 0);
  // Later frames are further from the gauge: more uncertain than the first frame.
  EXPECT_GT(last.ego_covariance(0, 0), out[1].ego_covariance(0, 0));
}

// The solver's and the marginalization's threads change nothing: every item's result goes to
// its own slot and the sums are taken in item order.
TEST(BackendSlidingWindow, SameEstimateOnOneAndTwoThreads) {
  const SimScene scene = streetScene();
  const auto inputs = scene.generate(25);
  BackendConfig c = streetConfig();
  c.compute_covariance = true;
  c.solver_threads = 1;
  SlidingWindow one(c);
  c.solver_threads = 2;
  SlidingWindow two(c);
  const auto a = run(one, inputs), b = run(two, inputs);
  ASSERT_EQ(a.size(), b.size());
  for (size_t f = 0; f < a.size(); ++f) {
    EXPECT_EQ(a[f].ego_pose.matrix(), b[f].ego_pose.matrix()) << "frame " << f;
    EXPECT_EQ(a[f].ego_covariance, b[f].ego_covariance) << "frame " << f;
    EXPECT_EQ(a[f].stats.final_cost, b[f].stats.final_cost) << "frame " << f;
    ASSERT_EQ(a[f].tracks.size(), b[f].tracks.size()) << "frame " << f;
    for (size_t k = 0; k < a[f].tracks.size(); ++k) {
      EXPECT_EQ(a[f].tracks[k].pose.matrix(), b[f].tracks[k].pose.matrix()) << "frame " << f << " track " << k;
      EXPECT_EQ(a[f].tracks[k].covariance, b[f].tracks[k].covariance) << "frame " << f << " track " << k;
    }
  }
  EXPECT_GT(a.back().tracks.size(), 2u);
}

TEST(BackendSlidingWindow, RejectsFramesOutOfOrder) {
  SlidingWindow window{BackendConfig()};
  BackendInput in;
  in.frame = 5;
  window.process(in);
  EXPECT_THROW(window.process(in), std::invalid_argument);
}

// The reported velocity of a car behind 0.15 m box noise (RMSE from frame 20 on), driving at
// 13 m/s, or braking from 15 m/s at 3 m/s^2 for 4 s.
double velocityRmse(bool braking, const BackendConfig& c, double* mean_error_braking = nullptr) {
  auto speed = [braking](double t) { return braking ? std::max(3.0, 15.0 - 3.0 * t) : 13.0; };
  SimScene scene;
  scene.ego = constantTwist(Pose::Identity(), 10.0, 0.0);
  SimObject car;
  car.id = 1;
  car.pose = [braking](double t) {
    if (!braking) return planarPose(15 + 13.0 * t, 3.5, 0);
    const double tb = std::min(t, 4.0);  // 15 m/s - 3 m/s^2 x 4 s = 3 m/s
    return planarPose(15 + 15.0 * tb - 1.5 * tb * tb + 3.0 * (t - tb), 3.5, 0);
  };
  car.dynamic_guess = true;
  scene.objects = {car};
  scene.box_noise = Eigen::Vector3d(0.15, 0.15, 0.05);
  scene.yaw_noise = 0.02;
  scene.seed = 4;
  SlidingWindow window(c);
  double sum = 0, signed_sum = 0;
  int n = 0, n_braking = 0;
  for (const BackendInput& in : scene.generate(80)) {
    const BackendOutput out = window.process(in);
    if (in.frame < 20) continue;
    for (const TrackEstimate& e : out.tracks) {
      const double truth = speed(scene.time(in.frame));
      sum += (e.velocity.head<2>() - Eigen::Vector2d(truth, 0.0)).squaredNorm();
      ++n;
      if (in.frame < 38) signed_sum += e.velocity.x() - truth, ++n_braking;  // braking until frame 40
    }
  }
  EXPECT_GT(n, 50);
  if (mean_error_braking) *mean_error_braking = signed_sum / std::max(1, n_braking);
  return std::sqrt(sum / n);
}

TEST(BackendWindow, ConstantAccelerationFactorFollowsABrakingCar) {
  const BackendConfig with = streetConfig();
  BackendConfig without = with;
  without.constant_acceleration_sigma.setConstant(1e3);
  const double steady = velocityRmse(false, with), braking = velocityRmse(true, with),
               braking_without = velocityRmse(true, without);
  std::printf("velocity RMSE: steady %.3f m/s, braking %.3f m/s (%.3f without the constant-acceleration factor)\n",
              steady, braking, braking_without);
  EXPECT_LT(steady, 0.3);
  EXPECT_LT(braking, 0.85 * braking_without);
}

// While the car brakes at 3 m/s^2, a window that drops the constant-acceleration factors at its
// edge keeps only eq. 11's random-walk velocity across the slide: its newest velocity trails the
// car's (a steady error of the acceleration times the filter's lag). Marginalized, the prior
// keeps the acceleration and the bias shrinks (eq. 11 itself still pulls toward no acceleration:
// measured +0.77 m/s dropped, +0.56 m/s kept).
TEST(BackendWindow, MarginalizedAccelerationRemovesTheLagBehindABrakingCar) {
  BackendConfig kept = streetConfig(), dropped = kept;
  kept.marginalize_acceleration = true;
  dropped.marginalize_acceleration = false;
  double bias_kept = 0, bias_dropped = 0;
  const double rmse_kept = velocityRmse(true, kept, &bias_kept), rmse_dropped = velocityRmse(true, dropped, &bias_dropped);
  std::printf("braking car: velocity RMSE %.3f m/s (mean error %+.3f) with the acceleration kept, %.3f (%+.3f) dropped\n",
              rmse_kept, bias_kept, rmse_dropped, bias_dropped);
  EXPECT_GT(bias_dropped, 0.5);  // trails: faster than the braking car
  EXPECT_LT(std::abs(bias_kept), 0.8 * bias_dropped);
  EXPECT_LT(rmse_kept, rmse_dropped);
}

// The shipped eq. 11 sigma (0.1 m along, 0.06 m across; config/dlslot.yaml): the window's nine
// eq. 11 factors on one nearly constant acceleration act as a prior of 3.3 m/s^2, no longer
// holding a car braking at 3 m/s^2 back (0.05 m: 1.7 m/s^2, half of it; measured mean error while
// braking +0.56 -> +0.25 m/s), at the price of a steady car's velocity 10 % noisier (0.19 -> 0.21).
TEST(BackendWindow, TheAccelerationPriorLetsABrakingCarBrake) {
  BackendConfig loose = streetConfig();
  loose.marginalize_acceleration = true;
  BackendConfig tight = loose;
  loose.constant_velocity_sigma.head<2>() = Eigen::Vector2d(0.1, 0.06);
  tight.constant_velocity_sigma.head<2>() = Eigen::Vector2d(0.05, 0.03);
  double bias_loose = 0, bias_tight = 0;
  const double rmse_loose = velocityRmse(true, loose, &bias_loose), rmse_tight = velocityRmse(true, tight, &bias_tight);
  const double steady_loose = velocityRmse(false, loose), steady_tight = velocityRmse(false, tight);
  std::printf("braking car: velocity RMSE %.3f m/s (mean error %+.3f) with eq. 11 at 0.1 m, %.3f (%+.3f) at 0.05 m; "
              "steady %.3f / %.3f\n",
              rmse_loose, bias_loose, rmse_tight, bias_tight, steady_loose, steady_tight);
  EXPECT_LT(std::abs(bias_loose), 0.6 * std::abs(bias_tight));
  EXPECT_LT(rmse_loose, rmse_tight);
  EXPECT_LT(steady_loose, 1.2 * steady_tight);
  EXPECT_LT(steady_loose, 0.3);
}

// A car overtaking on the highway at 27 m/s in the next lane, boxes 0.15 m and 0.04 rad off (the
// simulator's and PointRCNN's cars): the velocity's sideways error (its direction: the chain's
// heading) in frames 9-15, as its chain comes to span the window, over ten drives, with the chain
// started straight (yaw rate prior 1 m/s^2 over its speed) or free (measured 0.175 / 0.285 m/s).
namespace {
// One moving car whose boxes are as far off as the simulator's and PointRCNN's (0.15 m, 0.04 rad).
SimScene oneCarScene(std::function<Pose(double)> pose, unsigned seed) {
  SimScene scene;
  SimObject car;
  car.id = 1;
  car.pose = std::move(pose);
  car.dynamic_guess = true;
  scene.objects = {car};
  scene.box_noise = Eigen::Vector3d(0.15, 0.15, 0.05);
  scene.yaw_noise = 0.04;
  scene.seed = seed;
  return scene;
}

// The shipped chain: the acceleration kept across the slide, eq. 11 at 0.1 m along, 0.06 across.
BackendConfig shippedChainConfig() {
  BackendConfig c = streetConfig();
  c.marginalize_acceleration = true;
  c.constant_velocity_sigma.head<2>() = Eigen::Vector2d(0.1, 0.06);
  return c;
}

double youngSidewaysVelocityRmse(double lateral_acceleration) {
  double sum = 0;
  int n = 0;
  for (unsigned seed = 1; seed <= 10; ++seed) {
    SimScene scene = oneCarScene([](double t) { return planarPose(12 + 27.0 * t, 3.5, 0.0); }, seed);
    scene.ego = constantTwist(Pose::Identity(), 25.0, 0.0);
    BackendConfig c = shippedChainConfig();
    c.vehicle_acceleration = lateral_acceleration;
    SlidingWindow window(c);
    for (const BackendInput& in : scene.generate(16)) {
      const BackendOutput out = window.process(in);
      if (in.frame < 9) continue;
      for (const TrackEstimate& e : out.tracks) sum += e.velocity.y() * e.velocity.y(), ++n;
    }
  }
  EXPECT_GT(n, 50);
  return std::sqrt(sum / n);
}
}  // namespace

TEST(BackendWindow, AYoungCarsChainStartsStraight) {
  const double straight = youngSidewaysVelocityRmse(1.0), free = youngSidewaysVelocityRmse(0.0);
  std::printf("young car at 27 m/s: sideways velocity RMSE %.3f m/s started straight, %.3f free\n", straight, free);
  EXPECT_LT(straight, 0.7 * free);
}

// A van turning in at 5 m/s, 15 m ahead of the parked ego (the real slice's van): straight for 2 s,
// then its yaw rate builds to 0.25 rad/s over 1 s (1.25 m/s^3 of sideways jerk) and holds; boxes
// 0.15 m and 0.04 rad off. The velocity's error across the truth's direction while it turns
// (2.5-4 s), over ten drives, with eq. 11's yaw sigma from a sideways jerk of 1 m/s^3 at the
// van's speed (0.002 rad) or the fixed 0.0005 rad that suits a lane change at 25 m/s; and a car
// at 25 m/s on a straight line, whose sigma the rule barely changes (0.0004).
namespace {
Pose turningVan(double t) {
  // Heading and position integrated in 1 ms steps (the yaw rate is piecewise linear in t).
  const double speed = 5.0, t0 = 2.0, ramp = 1.0, rate = 0.25, h = 1e-3;
  double x = 5.0, y = 15.0, yaw = 0.0;
  for (double s = 0; s < t; s += h) {
    const double step = std::min(h, t - s);
    x += speed * std::cos(yaw) * step;
    y += speed * std::sin(yaw) * step;
    yaw += rate * std::clamp((s - t0) / ramp, 0.0, 1.0) * step;
  }
  return planarPose(x, y, yaw);
}

double sidewaysVelocityRmse(double jerk, bool turning) {
  double sum = 0;
  int n = 0;
  for (unsigned seed = 1; seed <= 10; ++seed) {
    const SimScene scene = oneCarScene(
        turning ? std::function<Pose(double)>(turningVan) : constantTwist(planarPose(10, 3.5, 0), 25.0, 0.0), seed);
    const SimObject& car = scene.objects.front();
    BackendConfig c = shippedChainConfig();
    c.vehicle_acceleration = 1.0;
    c.vehicle_lateral_jerk = jerk;
    SlidingWindow window(c);
    for (const BackendInput& in : scene.generate(turning ? 41 : 30)) {
      const BackendOutput out = window.process(in);
      if (in.frame < (turning ? 25 : 12)) continue;
      const double t = scene.time(in.frame), dt = 1e-3;
      const Eigen::Vector3d d = car.pose(t + dt).translation() - car.pose(t - dt).translation();
      const Eigen::Vector2d across = Eigen::Vector2d(-d.y(), d.x()).normalized();
      for (const TrackEstimate& e : out.tracks) sum += std::pow(across.dot(e.velocity.head<2>()), 2), ++n;
    }
  }
  EXPECT_GT(n, 100);
  return std::sqrt(sum / n);
}
}  // namespace

TEST(BackendWindow, ASlowVehiclesTurnIsFollowedAtItsSpeedsYawSigma) {
  const double by_speed = sidewaysVelocityRmse(1.0, true), fixed = sidewaysVelocityRmse(0.0, true);
  const double straight_by_speed = sidewaysVelocityRmse(1.0, false), straight_fixed = sidewaysVelocityRmse(0.0, false);
  std::printf("van turning in at 5 m/s: sideways velocity RMSE %.3f m/s with eq. 11's yaw sigma by its speed, %.3f "
              "fixed; a car at 25 m/s %.3f / %.3f\n",
              by_speed, fixed, straight_by_speed, straight_fixed);
  EXPECT_LT(by_speed, 0.8 * fixed);
  EXPECT_LT(straight_by_speed, 1.1 * straight_fixed);
}

// A car creeping away from a stop at 1.5 m/s, 15 m ahead, its boxes as noisy as the backend's
// model says (0.16 m there): three boxes cannot tell it from a parked car, its registered points
// can. Over ten drives, how often its track starts dynamic (and is published moving).
namespace {
int startsMoving(bool with_points) {
  int dynamic = 0;
  for (unsigned seed = 1; seed <= 10; ++seed) {
    SimScene scene;  // the ego stopped at the origin
    scene.seed = seed;
    SimObject car;
    car.id = 1;
    car.size = kCar;
    car.pose = constantTwist(planarPose(15.0, 3.5, 0.0, -1.73 + 0.75), 1.5, 0.0);
    scene.objects = {car};
    scene.box_noise = Eigen::Vector3d(0.16, 0.16, 0.05);
    BackendConfig c = streetConfig();
    c.observation_sigma_growth_per_m = 0.035;
    c.registration_types = {"Car"};
    SlidingWindow window(c);
    std::mt19937 rng(seed);
    for (BackendInput in : scene.generate(4)) {
      if (with_points)
        for (ObservationInput& o : in.observations)
          o.points = std::make_shared<const ObjectPoints>(
              scanBox(scene.objectTruth(1, in.frame), kCar, Eigen::Vector3d::Zero(), rng));
      const BackendOutput out = window.process(in);
      if (in.frame == 3 && !out.tracks.empty()) dynamic += out.tracks[0].dynamic;
    }
  }
  return dynamic;
}
}  // namespace

TEST(BackendWindow, ACreepingCarsPointsStartItMovingWhereItsBoxesCannot) {
  const int with = startsMoving(true), without = startsMoving(false);
  std::printf("creeping car started dynamic on %d of 10 drives with its points, %d without\n", with, without);
  EXPECT_GE(with, 9);
  EXPECT_LE(without, 5);
}

namespace {
// A street config whose box noise grows with range (0.105 m, 3.5 % per metre), and the scene's
// boxes as noisy as that model says at `range`.
BackendConfig noiseAsModelled(SimScene& scene, double range) {
  BackendConfig c = streetConfig();
  c.observation_sigma.head<2>() = Eigen::Vector2d(0.105, 0.105);
  c.observation_sigma_growth_per_m = 0.035;
  const double sigma = 0.105 * c.observationNoiseGrowth(range);
  scene.box_noise = Eigen::Vector3d(sigma, sigma, 0.05);
  return c;
}
}  // namespace

// A car queued 85 m ahead creeping at 3 m/s and a parked one beside it, their boxes as noisy as
// the backend's model says there (0.42 m): over 1000 drives, how often each starts dynamic on its
// first 4 boxes. Its 4-box fit's sigma is 1.87 m/s: tested in the plane at 2 sigmas the creeping
// car would start moving on 46 % of the drives, along its heading at the same false alarm (1.49
// sigmas) it does on 55 %; the parked car starts moving on 13.5 % either way.
TEST(BackendWindow, AFarCreepingCarIsJudgedByItsSpeedAlongItsHeading) {
  const int drives = 1000;
  int creeping = 0, parked = 0;
  for (unsigned seed = 1; seed <= drives; ++seed) {
    SimScene scene;  // the ego stopped at the origin
    scene.seed = seed;
    scene.init_after = 4;  // as the tracker confirms a track: on its 4th box
    SimObject queued, still;
    queued.id = 1;
    queued.pose = constantTwist(planarPose(85.0, 0.0, 0.0), 3.0, 0.0);
    still.id = 2;
    still.pose = [](double) { return planarPose(85.0, 8.0, 0.0); };
    scene.objects = {queued, still};
    const BackendConfig c = noiseAsModelled(scene, 85.0);
    scene.yaw_noise = 0.04;
    SlidingWindow window(c);
    for (const BackendInput& in : scene.generate(4)) {
      const BackendOutput out = window.process(in);
      if (in.frame != 3) continue;
      for (const TrackEstimate& e : out.tracks) (e.id == 1 ? creeping : parked) += e.dynamic;
    }
  }
  std::printf("far car creeping at 3 m/s started dynamic on %d of %d drives, a parked one on %d\n", creeping, drives,
              parked);
  EXPECT_GE(creeping, 0.51 * drives);
  EXPECT_LE(parked, 0.16 * drives);
}

// A car waiting 20 m ahead creeps off at 1.3 m/s at t = 2 s (its queue moves on) while a parked
// one waits beside it, their boxes as noisy as the backend's model says there (0.18 m). A
// landmark follows its boxes, which leave it slowly; the car's points measure the creep at once.
// Over ten drives: the frames from the creep's start to the car's first frame published moving
// (drives where it was started moving while still left out), and the frames the parked car is
// published moving.
namespace {
struct CreepOff {
  std::vector<int> delays;  // frames
  int parked_moving = 0;    // frames
};
CreepOff creepOff(bool with_points) {
  CreepOff result;
  const int frames = 40, start = 20;
  for (unsigned seed = 1; seed <= 10; ++seed) {
    SimScene scene;  // the ego stopped at the origin
    scene.seed = seed;
    SimObject car, parked;
    car.id = 1;
    car.size = parked.size = kCar;
    car.pose = [](double t) { return planarPose(20.0 + 1.3 * std::max(t - 2.0, 0.0), 0.0, 0.0, -1.73 + 0.75); };
    parked.id = 2;
    parked.pose = [](double) { return planarPose(20.0, 6.0, 0.0, -1.73 + 0.75); };
    scene.objects = {car, parked};
    BackendConfig c = noiseAsModelled(scene, 20.0);
    scene.yaw_noise = 0.02;
    c.registration_types = {"Car"};
    c.switch_min_sigmas = 3.0;
    SlidingWindow window(c);
    std::mt19937 rng(seed);
    int moving_from = frames;
    for (BackendInput in : scene.generate(frames)) {
      if (with_points)
        for (ObservationInput& o : in.observations)
          o.points = std::make_shared<const ObjectPoints>(
              scanBox(scene.objectTruth(o.track_id, in.frame), kCar, Eigen::Vector3d::Zero(), rng));
      const BackendOutput out = window.process(in);
      for (const TrackEstimate& e : out.tracks) {
        if (e.id == 2) result.parked_moving += e.dynamic;
        if (e.id == 1 && e.dynamic && moving_from == frames) moving_from = in.frame;
      }
    }
    if (moving_from > start) result.delays.push_back(moving_from - start);
  }
  return result;
}
}  // namespace

TEST(BackendWindow, ACarCreepingOffIsSeenMovingByItsPointsFirst) {
  const CreepOff with = creepOff(true), without = creepOff(false);
  const auto text = [](const std::vector<int>& d) {
    std::string s;
    for (int x : d) s += std::to_string(x) + " ";
    return s;
  };
  std::printf("car creeping off: published moving after %sframes with its points, %swithout; the parked car "
              "moving in %d / %d frames\n",
              text(with.delays).c_str(), text(without.delays).c_str(), with.parked_moving, without.parked_moving);
  ASSERT_GE(with.delays.size(), 8u);
  ASSERT_EQ(with.delays.size(), without.delays.size());
  EXPECT_LE(*std::max_element(with.delays.begin(), with.delays.end()), 3);
  EXPECT_GE(*std::min_element(without.delays.begin(), without.delays.end()), 5);
  EXPECT_EQ(with.parked_moving, 0);
}

// Each track publishes its velocity's covariance: a young one its boxes' line's (fused with its
// points' motion when it has them), a mature one the joint covariance of the chain's two poses
// it differences. A car 30 m away at 11 m/s, its boxes as noisy as the backend's model says, over
// 40 drives. A young track's line is a plain least-squares fit: its errors fall inside the 95 %
// ellipse 95 % of the time. A mature chain's covariance is its motion prior's (eq. 11 lets a car
// change its speed far more than this one does): never overconfident, and within a factor of 3 of
// its errors. Without the two poses' cross-covariance its sigma would be 2.6 m/s, 10x the errors.
TEST(BackendWindow, ATracksVelocityCovarianceTellsItsErrors) {
  struct Tally {
    int n = 0, within = 0;
    double variance = 0, squared_error = 0;  // sums of the covariance's trace / 2, of |error|^2 / 2
    double within95() const { return static_cast<double>(within) / n; }
    double sigma() const { return std::sqrt(variance / n); }
    double rms() const { return std::sqrt(squared_error / n); }
  };
  Tally young, mature;
  for (unsigned seed = 1; seed <= 40; ++seed) {
    SimScene scene;
    scene.seed = seed;
    scene.ego = constantTwist(Pose::Identity(), 10.0, 0.0);
    SimObject car;
    car.id = 1;
    car.pose = constantTwist(planarPose(30.0, 3.5, 0.0), 11.0, 0.0);
    car.dynamic_guess = true;
    scene.objects = {car};
    BackendConfig c = noiseAsModelled(scene, 30.0);
    c.compute_covariance = true;
    scene.yaw_noise = c.observation_sigma[5];
    SlidingWindow window(c);
    for (const BackendInput& in : scene.generate(50)) {
      for (const TrackEstimate& e : window.process(in).tracks) {
        if (e.age >= 5 && e.age < 20) continue;
        Tally& t = e.age < 5 ? young : mature;
        const Eigen::Matrix2d C = e.velocity_covariance.topLeftCorner<2, 2>();
        const Eigen::Vector2d err = e.velocity.head<2>() - Eigen::Vector2d(11.0, 0.0);
        ASSERT_GT(C.determinant(), 0.0) << "age " << e.age;
        ++t.n;
        t.within += err.dot(C.inverse() * err) <= 5.991;  // chi-square, 2 degrees of freedom, 95 %
        t.variance += 0.5 * C.trace();
        t.squared_error += 0.5 * err.squaredNorm();
      }
    }
  }
  for (const Tally* t : {&young, &mature})
    std::printf("%s: %d of %d velocity errors inside the 95 %% ellipse; sigma %.3f m/s, errors %.3f m/s RMS per axis\n",
                t == &young ? "young (< 5 scans)" : "mature (20+ scans)", t->within, t->n, t->sigma(), t->rms());
  ASSERT_GT(young.n, 80);
  ASSERT_GT(mature.n, 800);
  EXPECT_NEAR(young.within95(), 0.95, 0.05);
  EXPECT_GE(mature.within95(), 0.95);
  EXPECT_LT(mature.sigma(), 3.0 * mature.rms());
  EXPECT_GT(young.sigma(), mature.sigma());
}

// A car followed for 2.5 s, then hidden while it brakes at 2 m/s^2 (twice the RMS acceleration the
// backend assumes): its coasting velocity stays the one it was last seen with, and its covariance
// grows with the time unseen so that the braking stays inside the 95 % ellipse. The chain's own
// covariance (sigma 0.59 m/s) leaves the truth outside after 0.9 s.
TEST(BackendWindow, ACoastingCarsVelocityCovarianceGrowsWhileItIsUnseen) {
  constexpr double kSpeed = 11.0, kBraking = 2.0, kHiddenAt = 2.5;  // m/s, m/s^2, s
  SimScene scene;
  scene.ego = constantTwist(Pose::Identity(), 10.0, 0.0);
  SimObject car;
  car.id = 1;
  car.pose = constantTwist(planarPose(30.0, 3.5, 0.0), kSpeed, 0.0);  // only seen before it brakes
  car.visible = [](int f) { return f < 25; };
  car.dynamic_guess = true;
  scene.objects = {car};
  BackendConfig c = noiseAsModelled(scene, 30.0);
  c.compute_covariance = true;
  c.vehicle_acceleration = 1.0;  // the shipped figure
  SlidingWindow window(c);
  int coasting = 0;
  double first_sigma = 0, last_sigma = 0;
  for (const BackendInput& in : scene.generate(35))
    for (const TrackEstimate& e : window.process(in).tracks) {
      if (e.status != TrackStatus::Coasting) continue;
      const double unseen_s = 0.1 * in.frame - kHiddenAt;
      const Eigen::Vector2d err = e.velocity.head<2>() - Eigen::Vector2d(kSpeed - kBraking * unseen_s, 0.0);
      const Eigen::Matrix2d C = e.velocity_covariance.topLeftCorner<2, 2>();
      EXPECT_LE(err.dot(C.inverse() * err), 5.991) << "frame " << in.frame << ", error " << err.norm() << " m/s";
      (coasting++ == 0 ? first_sigma : last_sigma) = std::sqrt(C(0, 0));
    }
  ASSERT_GE(coasting, 8);
  // Its variance grew by (1 m/s^2 x the time unseen)^2: from 0.1 s at the first coasting frame to
  // 0.1 x coasting s at the last.
  EXPECT_NEAR(last_sigma * last_sigma - first_sigma * first_sigma, 0.01 * (coasting * coasting - 1), 0.02);
}
