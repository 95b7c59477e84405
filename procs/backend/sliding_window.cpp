#include "backend/sliding_window.hpp"

#include <ceres/loss_function.h>

#include <chrono>
#include <limits>
#include <set>
#include <stdexcept>

#include "backend/constant_acceleration_factor.hpp"
#include "backend/constant_velocity_factor.hpp"
#include "backend/face_heading_factor.hpp"
#include "backend/landmark_observation_factor.hpp"
#include "backend/marginalization_prior.hpp"
#include "backend/motion_evidence.hpp"
#include "backend/object_points.hpp"
#include "backend/observation_factor.hpp"
#include "backend/odometry_factor.hpp"
#include "backend/pose_change_factor.hpp"
#include "backend/registered_velocity.hpp"
#include "backend/registration_factor.hpp"
#include "backend/sight_speed_factor.hpp"
#include "backend/vehicle_motion_factor.hpp"
#include "dlslot/deskew.hpp"

namespace dlslot::backend {
namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

std::shared_ptr<ceres::LossFunction> makeLoss(const std::string& name, double scale) {
  if (name == "huber") return std::make_shared<ceres::HuberLoss>(scale);
  if (name == "cauchy") return std::make_shared<ceres::CauchyLoss>(scale);
  return nullptr;
}

// SE(3) interpolation a * Exp(s Log(a^-1 b)) with [t; Log(R)] coordinates of a^-1 b.
Pose interpolate(const Pose& a, const Pose& b, double s) {
  const Vector6 d = logPose(a.inverse() * b);
  Pose step = Pose::Identity();
  step.linear() = expSO3(s * d.tail<3>()).toRotationMatrix();
  step.translation() = s * d.head<3>();
  return a * step;
}

// c^n for a per-frame pose change c (predicting an object n frames ahead).
Pose power(const Pose& c, int n) {
  Pose out = Pose::Identity();
  for (int i = 0; i < n; ++i) out = out * c;
  return out;
}

}  // namespace

SlidingWindow::SlidingWindow(BackendConfig config)
    : config_(std::move(config)),
      parallel_(config_.solver_threads),
      marginalizer_(&parallel_),
      observation_loss_(makeLoss(config_.observation_loss, config_.observation_loss_scale)) {}

SlidingWindow::~SlidingWindow() = default;

BackendOutput SlidingWindow::process(const BackendInput& in) {
  if (in.frame <= last_frame_)
    throw std::invalid_argument("backend: frame " + std::to_string(in.frame) + " after frame " + std::to_string(last_frame_));
  const auto t0 = Clock::now();
  last_frame_ = in.frame;
  BackendOutput out;
  out.frame = in.frame;
  out.utime = in.utime;
  out.odometry_missing = !in.odometry.has_value();
  out.associations_missing = in.associations_missing;

  addEgoFrame(in, out);
  if (config_.mode != Mode::kOdometryOnly) {
    addObservations(in, out);
    out.static_to_dynamic = switchMovingLandmarks();
  }
  solve(out);
  out.ego_pose = fromBlock(frames_.back().pose->data());
  if (static_cast<int>(frames_.size()) >= config_.window_size) {
    const auto t1 = Clock::now();
    out.smoothed = slide();
    out.stats.marginalize_ms = msSince(t1);
  }
  out.stats.prior_dim = priorDimension();
  out.stats.total_ms = msSince(t0);
  return out;
}

// ---- step 1: the ego pose and its odometry factor (eq. 8) ----

void SlidingWindow::addEgoFrame(const BackendInput& in, BackendOutput& out) {
  const bool have_odometry = in.odometry.has_value();
  const Pose delta = have_odometry ? in.odometry->delta : last_delta_;
  Pose X;
  if (frames_.empty()) {
    X = have_odometry ? in.odometry->pose : Pose::Identity();
  } else if (config_.mode == Mode::kSlot || !have_odometry) {
    X = fromBlock(frames_.back().pose->data()) * delta;
  } else {
    X = in.odometry->pose;  // two-stage / odometry-only: the odometry's pose as it is
  }
  const bool odometry_factor = config_.mode == Mode::kSlot && !frames_.empty();
  Matrix6 S = sqrtInformation(config_.odometry_sigma);
  if (odometry_factor) {
    const bool degraded = !have_odometry || !in.odometry->ok;
    if (degraded) {
      // A missing or fallen-back odometry: the constant-velocity prediction with the configured
      // sigmas times degraded_odometry_scale. Not the message's covariance: a fallback publishes
      // its own wide placeholder (1 m), and scaled again it let moving objects alone, which
      // cannot fix the ego's velocity, push a stopped ego along at 4 m/s.
      S /= config_.degraded_odometry_scale;
    } else if (config_.use_odometry_covariance) {
      Eigen::LLT<Matrix6> llt(in.odometry->covariance);
      // S = L^-1 with Sigma = L L^T gives S^T S = Sigma^-1; the covariance D Sigma D, with D the
      // translation and rotation scale factors, has S D^-1.
      Vector6 scale;
      scale << config_.odometry_covariance_scale.x() * Eigen::Vector3d::Ones(), config_.odometry_covariance_scale.y() * Eigen::Vector3d::Ones();
      if (llt.info() == Eigen::Success && in.odometry->covariance.allFinite())
        S = llt.matrixL().solve(Matrix6::Identity()) * scale.cwiseInverse().asDiagonal();
    }
    // The factor against the objects' view of the same motion. Only a frame that fails the test
    // changes: its translation covariance times the inflation (S D^-1 as above, D = sqrt(k) on
    // translation), its pose started from the objects' translation. A frame that passes keeps
    // the factor and the start it had without the test, so its solution is bit-identical.
    out.odometry_check = checkOdometryFactor(in, delta, S);
    if (out.odometry_check.outcome == OdometryCheckOutcome::kDownweighted) {
      Vector6 scale;
      scale << std::sqrt(out.odometry_check.inflation) * Eigen::Vector3d::Ones(), Eigen::Vector3d::Ones();
      S = S * scale.cwiseInverse().asDiagonal();
      Pose T = delta;
      T.translation() = out.odometry_check.translation;
      X = fromBlock(frames_.back().pose->data()) * T;
    }
  }
  EgoFrame f;
  f.frame = in.frame;
  f.utime = in.utime;
  double* x = newBlock(f.pose, X);
  double* x_prev = frames_.empty() ? nullptr : frames_.back().pose->data();
  frames_.push_back(std::move(f));
  last_delta_ = delta;

  if (config_.mode != Mode::kSlot) {
    fixed_.insert(x);
    return;
  }
  if (!x_prev) {
    // The first pose fixes the gauge (world = the first scan's frame).
    addFactor(MarginalizationPrior::CreatePosePrior(X, sqrtInformation(config_.first_pose_sigma)), false, {x});
    return;
  }
  addFactor(OdometryFactor::Create(delta, S), false, {x_prev, x});
}

OdometryCheck SlidingWindow::checkOdometryFactor(const BackendInput& in, const Pose& delta, const Matrix6& S) const {
  const EgoFrame& prev = frames_.back();
  const Pose X_prev = fromBlock(prev.pose->data());
  const double dt = 1e-6 * static_cast<double>(in.utime - prev.utime);
  const Eigen::Matrix3d R = delta.linear();
  // A box's centre covariance in the lidar frame: the factor's sigmas along and across the box
  // (observation_factor.hpp), grown with range as the factor's are.
  const auto boxCovariance = [&](const Pose& b, const Vector6& sigma) -> Eigen::Matrix3d {
    const Eigen::Vector3d s = sigma.head<3>() * config_.observationNoiseGrowth(b.translation().norm());
    return b.linear() * s.cwiseAbs2().asDiagonal() * b.linear().transpose();
  };
  std::vector<MotionEvidence> evidence;
  std::unordered_set<int> used;
  for (const ObservationInput& obs : in.observations) {
    // The objects the graph uses (initialized, confirmed), seen in the previous frame too.
    if (obs.track_id < 0 || !obs.initialized || !obs.confirmed || !used.insert(obs.track_id).second) continue;
    const auto it = tracks_.find(obs.track_id);
    if (it == tracks_.end() || it->second.model == TrackModel::kNotInGraph) continue;
    const Track& track = it->second;
    const auto before = track.observations.find(prev.frame);
    if (before == track.observations.end() || !before->second.in_graph) continue;
    const bool moving = track.model == TrackModel::kDynamic;
    if (moving && (!track.velocity || !(dt > 0))) continue;
    const Pose& b_prev = before->second.b;
    const Pose b_cur = obs.box.pose();
    const Vector6 sigma = config_.boxSigma(track.type, moving);
    MotionEvidence e;
    e.track_id = obs.track_id;
    e.moving = moving;
    e.translation = b_prev.translation() - R * b_cur.translation();
    e.covariance = boxCovariance(b_prev, sigma) + R * boxCovariance(b_cur, sigma) * R.transpose();
    if (moving) {
      // Its velocity before this frame (world), and eq. 11's sigma: how much its per-frame motion
      // may change from one frame to the next, along and across its heading.
      e.translation += X_prev.linear().transpose() * *track.velocity * dt;
      const Eigen::Vector3d s = config_.constant_velocity_sigma.head<3>();
      e.covariance += b_prev.linear() * s.cwiseAbs2().asDiagonal() * b_prev.linear().transpose();
    }
    evidence.push_back(e);
  }
  // The odometry's translation covariance from the factor's information S^T S; the factor's
  // error (X_{t-1}^-1 X_t)^-1 T has its translation in the axes of frame t, turned into t-1's.
  const Matrix6 covariance = (S.transpose() * S).inverse();
  const Eigen::Matrix3d C = R * covariance.topLeftCorner<3, 3>() * R.transpose();
  return checkOdometry(delta.translation(), C, evidence, config_.odometry_check);
}

// ---- step 2: observations, eq. 9-11 with eq. 12's membership ----

void SlidingWindow::addObservations(const BackendInput& in, BackendOutput& out) {
  const Pose X = fromBlock(frames_.back().pose->data());
  // The scan's points of each detection, and of each moving vehicle the detector missed in it,
  // cropped in one pass over the scan.
  std::vector<ObservationInput> observations = in.observations;
  const size_t detected = observations.size();
  if (in.scan) {
    if (config_.registration_missed_vehicles) addMissedVehicles(observations, in.frame, X);
    attachObjectPoints(*in.scan, config_, observations);
  }
  for (size_t i = 0; i < detected; ++i) {
    const ObservationInput& obs = observations[i];
    if (obs.track_id < 0) continue;
    Track& track = tracks_[obs.track_id];
    if (track.observations.count(in.frame)) continue;  // one detection per track and frame
    if (track.id < 0) {
      track.id = obs.track_id;
      first_seen_.emplace(obs.track_id, in.frame);
    }
    track.type = obs.box.type;
    // Running mean of the box size, weighted towards recent boxes after a while.
    track.size_samples = std::min(track.size_samples + 1, 20);
    track.size += (obs.box.size - track.size) / track.size_samples;
    track.last_seen = in.frame;
    track.dynamic_guess = obs.dynamic_guess;
    track.confidence = obs.confidence;
    const Pose b = alignedBox(track, X, obs.box);
    // alignedBox turned the box round when it pointed against the track: its vote on the front.
    track.front = withDetection(track.front, obs.box.yaw, yawOf(b.linear()));
    track.observations[in.frame] = Observation{b, false};
    registerPoints(track, obs, in.frame, X, out);
    // Not in O_init yet, or not confirmed by the tracker's lifecycle (a likely false positive):
    // evidence only, never in the graph where it could pull the ego poses.
    if (!obs.initialized || !obs.confirmed) continue;
    if (track.model == TrackModel::kNotInGraph) startTrack(track, in.frame);
    addTrackObservation(track, in.frame);
  }
  // A missed vehicle's points are measured as a detection's; its predicted box is no observation.
  for (size_t i = detected; i < observations.size(); ++i) {
    const ObservationInput& obs = observations[i];
    if (!obs.points || obs.points->empty()) continue;
    registerPoints(tracks_.at(obs.track_id), obs, in.frame, X, out);
    ++out.missed_vehicles_measured;
  }
}

void SlidingWindow::addMissedVehicles(std::vector<ObservationInput>& observations, int frame, const Pose& X) const {
  // The detector misses far vehicles whose points the scan holds (its recall falls with their
  // points): of the frames of moving vehicles beyond 60 m on the simulated highway and highway-jam
  // (seed 6), 30 % had a scan missed among their last four, which broke the face's pairs and the
  // registration's chain of scans. A moving vehicle is cropped from the scan where its chain
  // predicts it: its newest pose moved on by its velocity. Only while that prediction's standard
  // deviation (its velocity's times the time since it was seen) is within half the crop's margin:
  // beyond, the crop may hold a neighbour and miss the vehicle's far face.
  std::set<int> seen;
  for (const ObservationInput& obs : observations) seen.insert(obs.track_id);
  for (const auto& [id, track] : tracks_) {
    if (track.model != TrackModel::kDynamic || !registers(track.type) || seen.count(id) || track.poses.empty() ||
        !track.velocity)
      continue;
    const auto last = track.poses.rbegin();
    const double gap = secondsBetween(last->first, frame);
    Pose o = fromBlock(last->second->data());
    o.translation() += *track.velocity * gap;
    const Pose b = X.inverse() * o;
    ObservationInput obs;
    obs.track_id = id;
    obs.box.type = track.type;
    obs.box.center = b.translation();
    obs.box.yaw = yawOf(b.linear());
    obs.box.size = track.size;
    const double margin =
        std::max(config_.registration_box_margin,
                 config_.registration_box_margin_sigmas * config_.boxLengthwiseSigma(obs.box.center.norm()));
    const double sigma = std::sqrt(track.velocity_covariance.topLeftCorner<2, 2>().trace()) * gap;
    if (gap > 0 && sigma <= 0.5 * margin) observations.push_back(obs);
  }
}

bool SlidingWindow::registers(const std::string& type) const {
  return std::find(config_.registration_types.begin(), config_.registration_types.end(), type) !=
         config_.registration_types.end();
}

void SlidingWindow::registerPoints(Track& track, const ObservationInput& obs, int frame, const Pose& X, BackendOutput& out) {
  if (!obs.points || !registers(track.type)) return;
  const RegistrationOptions& options = config_.registration;
  const EgoFrame* prev_ego = findFrame(frame - 1);
  const double frame_dt = prev_ego ? 1e-6 * static_cast<double>(frames_.back().utime - prev_ego->utime) : 0.0;
  // The object's velocity over ground: its last estimate, else the line through its boxes (a
  // young track's last two boxes, 0.1 s apart, put it 0.5-3 m a frame off on the simulated
  // highway-jam, outside the registration's 0.3 m reach; the line through 3-4 of them, 0.1-0.2 m).
  Eigen::Vector3d v_world = Eigen::Vector3d::Zero();
  bool have_velocity = static_cast<bool>(track.velocity);
  if (have_velocity) {
    v_world = *track.velocity;
  } else if (const std::optional<LineVelocity> line = boxLineVelocity(track)) {
    v_world = line->velocity;
    have_velocity = true;
  }
  // Each point is in the lidar frame of its firing, t seconds from the reference instant: the
  // lidar had moved by the ego's motion (its twist over the last frame, lidar frame), the object
  // by its velocity. Both undone to first order in t, so the points sit where the object's box
  // (and pose) is at the reference instant.
  BodyTwist ego;  // the lidar's, over the last frame (deskew.hpp; frame t-1's axes ~ frame t's)
  Eigen::Vector3d v_obj = Eigen::Vector3d::Zero();
  if (config_.sweep.period_s > 0 && frame_dt > 0) {
    ego = twistBetween(fromBlock(prev_ego->pose->data()), X, frame_dt);
    if (have_velocity) v_obj = X.linear().transpose() * v_world;
  }
  ObjectPoints world;
  world.reserve(obs.points->size());
  for (const Eigen::Vector3f& pf : *obs.points) {
    Eigen::Vector3d p = pf.cast<double>();
    // First order in t (deskew() takes the exact exponential for whole scans; here the few
    // hundred points of each object, and at 0.5 rad/s over half a sweep the two differ by < 1 mm).
    const double t = config_.sweep.firingTime(p.x(), p.y());
    p += t * (ego.angular.cross(p) + ego.velocity - v_obj);
    world.push_back((X * p).cast<float>());
  }
  if (config_.face_heading) {
    Box box = obs.box;
    box.center = X * obs.box.center;
    box.yaw = obs.box.yaw + yawOf(X.linear());
    if (std::optional<FaceHeading> face = faceHeading(world, box, X.translation())) {
      // Kept in the scan's axes, as the factor measures it (face_heading_factor.hpp).
      const Eigen::Vector3d h = X.linear().transpose() * Eigen::Vector3d(std::cos(face->yaw), std::sin(face->yaw), 0.0);
      face->yaw = std::atan2(h.y(), h.x());
      track.face_headings[frame] = *face;
    }
  }
  // The young path reads it (youngVehicleVelocity); a chain takes each pair as a factor when
  // line_of_sight_chain is set, and needs none otherwise.
  if (!track.velocity_from_chain || config_.line_of_sight_chain) {
    out.line_of_sight_pairs += measureLineOfSight(track, world, obs.box, frame, X, frame_dt);
    out.side_pairs += measureSideEnds(track, world, obs, frame, X);
  }
  const std::shared_ptr<const PreparedObject> previous = track.points;
  const int previous_frame = track.points_frame;
  const double range = obs.box.center.norm();
  // This scan prepared once (thinned, gridded, its planes). Without a model: this frame's target
  // and the next frame's source. With one: this frame's source, registered to the model of the
  // previous scans (the target, gridded only, as dense as the model is bounded), which then takes
  // this scan in.
  const bool with_model = options.model_frames > 1;
  const auto current = std::make_shared<const PreparedObject>(world, range, options);
  std::optional<Pose> measured;
  const auto keep = [&] {
    track.points_frame = frame;
    track.points_ego = X;
    track.accumulated.update(world, frame, measured, range, options);  // also the refined box's points
    if (!with_model) {
      track.points = current;
      return;
    }
    RegistrationOptions model_options = options;
    model_options.max_target_points = options.max_model_points;
    track.points = std::make_shared<const PreparedObject>(track.accumulated.points(), range, model_options, false);
  };
  if (!previous || previous_frame != frame - 1) {
    ++out.registration_no_previous;
    keep();
    return;
  }
  // The prediction: the chain's latest pose change carried to the world at o_{t-1}, else the
  // velocity above over the frame's time.
  Pose M0 = Pose::Identity();
  const auto o_prev = track.poses.find(frame - 1);
  if (track.model == TrackModel::kDynamic && o_prev != track.poses.end() && !track.changes.empty()) {
    const Pose o = fromBlock(o_prev->second->data());
    M0 = o * fromBlock(track.changes.rbegin()->second->data()) * o.inverse();
  } else if (have_velocity) {
    M0.translation() = v_world * frame_dt;
  }
  const RegistrationResult r =
      with_model ? registerToModel(*previous, *current, M0, options) : registerObject(*previous, *current, M0, options);
  ++out.registrations[static_cast<int>(r.outcome)];
  out.registration_points += r.source_points;
  if (r.ok()) out.registration_residual_sq += r.rms_residual * r.rms_residual;
  if (r.ok()) track.motions[frame] = Track::Motion{r.motion, r.information, track.points_ego, X};
  // Only a full measurement carries the model along: a partial one's unmeasured direction is the
  // prediction's (decimetres off), and older points moved by it would smear the model along the
  // face it could not see.
  if (r.outcome == RegistrationOutcome::kMeasured) measured = r.motion;
  keep();
}

bool SlidingWindow::measureLineOfSight(Track& track, const ObjectPoints& world, const Box& box, int frame, const Pose& X,
                                      double dt) const {
  if (config_.line_of_sight_pairs <= 0) return false;
  // The scans a pair is judged by, and the previous one a pair needs.
  track.sight_faces.erase(track.sight_faces.begin(),
                          track.sight_faces.lower_bound(frame - std::max(config_.line_of_sight_series, 2) + 1));
  if (static_cast<int>(world.size()) < config_.line_of_sight_young_min_points ||
      !facesTheSensor(box, config_.line_of_sight_max_angle_deg))
    return false;  // no pair across this scan
  // This scan's face along the previous scan's line of sight: the pair's speed.
  bool paired = false;
  if (const auto previous = track.sight_faces.find(frame - 1); previous != track.sight_faces.end() && dt > 0)
    if (const std::optional<double> range = nearFaceRange(world, previous->second.u)) {
      const Track::SightFace& face = previous->second;
      track.sight_speeds[frame] = PairSpeed{face.u.head<2>(), (*range - face.range) / dt, config_.line_of_sight_sigma,
                                            face.u.dot(X.translation() - face.sensor),
                                            static_cast<int>(std::min(face.points->size(), world.size())), std::nullopt};
      paired = true;
    }
  if (const std::optional<Eigen::Vector3d> u = lineOfSight(world, X.translation())) {
    track.sight_faces[frame] =
        Track::SightFace{std::make_shared<const ObjectPoints>(world), *u, *nearFaceRange(world, *u), X.translation()};
    judgeFacePairs(track, frame);
  }
  return paired;
}

void SlidingWindow::judgeFacePairs(Track& track, int frame) const {
  // The face's range along the newest line of sight in each kept scan; each pair whose two scans
  // are among them judged again, so a jump is held against both pairs it spoils, the one before it
  // too (a pair's verdict changes the young path's median, and the chain's factor when its frame
  // is added).
  const Eigen::Vector3d& u = track.sight_faces.at(frame).u;
  std::vector<int> frames;
  std::vector<double> t, y;
  for (const auto& [f, face] : track.sight_faces) {
    frames.push_back(f);
    t.push_back(-secondsBetween(f, frame));
    y.push_back(*nearFaceRange(*face.points, u));
  }
  const std::vector<bool> on = faceSamplesOnLine(t, y, config_.line_of_sight_tolerance);
  for (size_t i = 1; i < on.size(); ++i)
    if (frames[i - 1] == frames[i] - 1)
      if (const auto pair = track.sight_speeds.find(frames[i]); pair != track.sight_speeds.end())
        pair->second.on_line = on[i - 1] && on[i];
}

bool SlidingWindow::measureSideEnds(Track& track, const ObjectPoints& world, const ObservationInput& obs, int frame,
                                   const Pose& X) const {
  const Box& box = obs.box;
  const Eigen::Vector2d c = box.center.head<2>();
  if (config_.side_azimuth_step_deg <= 0 || config_.line_of_sight_pairs <= 0 || c.norm() < 1e-3 ||
      static_cast<int>(world.size()) < config_.line_of_sight_young_min_points ||
      facesTheSensor(box, config_.line_of_sight_max_angle_deg))
    return false;
  // The angle between the side and the line of sight widens the columns' spacing along it.
  const double yaw = box.yaw + yawOf(X.linear());
  track.side_scans[frame] = Track::SideScanPoints{
      std::make_shared<const ObjectPoints>(world), Eigen::Vector3d(std::cos(yaw), std::sin(yaw), 0.0),
      sideEndSigma(c.norm(), sideSine(box), config_.side_azimuth_step_deg * M_PI / 180.0, config_.registration.accuracy_m),
      obs.ends_seen, X.translation(), X * box.center, config_.boxLengthwiseSigma(c.norm())};
  const std::optional<PairSpeed> pair = sidePair(track, frame - 1, frame);
  if (pair) track.side_speeds[frame] = *pair;
  return pair.has_value();
}

std::optional<PairSpeed> SlidingWindow::sidePair(const Track& track, int f0, int f1) const {
  const auto previous = track.side_scans.find(f0), current = track.side_scans.find(f1);
  if (previous == track.side_scans.end() || current == track.side_scans.end()) return std::nullopt;
  const Track::SideScanPoints &a = previous->second, &b = current->second;
  const std::optional<SideView> view_a = sideView(track, a, a.d), view_b = sideView(track, b, a.d);
  if (!view_a || !view_b) return std::nullopt;
  std::optional<PairSpeed> p = sidePairSpeed(*view_a, *view_b, a.d.head<2>(), track.size.x(), config_.side_length_tolerance,
                                             secondsBetween(f0, f1));
  if (!p) return std::nullopt;
  p->sensor_displacement = a.d.dot(b.sensor - a.sensor);
  p->points = static_cast<int>(std::min(a.points->size(), b.points->size()));
  return p;
}

std::optional<SideView> SlidingWindow::sideView(const Track& track, const Track::SideScanPoints& scan,
                                                const Eigen::Vector3d& u) const {
  const std::optional<SideEnds> ends = sideEnds(*scan.points, u);
  if (!ends) return std::nullopt;
  const EndsSeen seen =
      endsThatCount(*ends, scan.seen.flipped(u.dot(scan.d) < 0), static_cast<int>(scan.points->size()), track.size.x(),
                    config_.side_length_tolerance, u.dot(scan.box_center), scan.box_sigma, config_.line_of_sight_min_points);
  return SideView{*ends, scan.end_sigma, seen};
}

std::optional<VelocityEvidence> SlidingWindow::sideVelocity(const Track& track) const {
  if (track.side_scans.size() < 2) return std::nullopt;
  const Eigen::Vector3d& d = track.side_scans.rbegin()->second.d;
  std::vector<SideScan> scans;
  for (const auto& [f, scan] : track.side_scans)
    if (const EgoFrame* ego = findFrame(f))
      if (const std::optional<SideView> view = sideView(track, scan, d))
        scans.push_back(SideScan{1e-6 * static_cast<double>(ego->utime), *view});
  const std::optional<SideLine> line = sideLine(scans, track.size.x(), config_.side_length_tolerance);
  if (!line) return std::nullopt;
  const double age = 1e-6 * static_cast<double>(frames_.back().utime) - line->time;
  const double variance = line->sigma * line->sigma + std::pow(config_.vehicle_acceleration * age, 2);
  VelocityEvidence v;
  v.velocity = line->speed * d.head<2>();
  v.information = d.head<2>() * d.head<2>().transpose() / variance;
  return v;
}

std::optional<SpeedFit> SlidingWindow::windowMotion(const Track& track,
                                                    const std::optional<WindowHeading>& heading) const {
  std::vector<TimedPosition> positions(track.past_boxes.begin(), track.past_boxes.end());
  double range_sum = 0;
  int in_window = 0;
  for (const auto& [f, obs] : track.observations) {
    const EgoFrame* ego = findFrame(f);
    if (!ego) continue;
    positions.push_back({1e-6 * static_cast<double>(ego->utime), fromBlock(ego->pose->data()) * obs.b.translation()});
    range_sum += obs.b.translation().norm();
    ++in_window;
  }
  // The boxes' noise at the window's mean range.
  const double range = in_window == 0 ? 0.0 : range_sum / in_window;
  const double sigma =
      0.5 * (config_.observation_sigma[0] + config_.observation_sigma[1]) * config_.observationNoiseGrowth(range);
  // Boxes more than 5 sigmas off the consensus line are another object's (the tracker's wrong
  // associations, often before a gap). 5 left every tuning run's velocity RMSE as it was but
  // highway-jam 3's (0.786 -> 0.556 m/s: an oncoming van whose first box was another's); 3 and 2
  // also dropped good boxes of young tracks (highway-jam 2: 0.515 -> 0.533 and 0.548 m/s).
  return fitSpeedAmongOutliers(positions, sigma, 5.0, heading ? &heading->direction : nullptr);
}

std::optional<SlidingWindow::WindowHeading> SlidingWindow::windowHeading(const Track& track) const {
  if (!isVehicle(track.type)) return std::nullopt;
  // Unit headings weighted by their inverse variances: a box's is its class's rz sigma, a face
  // fit's its own (a tenth of it, or less). A face does not know front from back: it is taken
  // along its box.
  const double box_weight = std::pow(config_.boxSigma(track.type, true)[5], -2);
  Eigen::Vector2d heading = Eigen::Vector2d::Zero();
  double weight = 0;
  for (const auto& [f, obs] : track.observations)
    if (const EgoFrame* ego = findFrame(f)) {
      const Eigen::Matrix3d R = fromBlock(ego->pose->data()).linear();
      const double yaw = yawOf(R * obs.b.linear());
      Eigen::Vector2d h(std::cos(yaw), std::sin(yaw));
      double w = box_weight;
      if (const auto face = track.face_headings.find(f); face != track.face_headings.end()) {
        const double a = face->second.yaw;  // in the scan's axes
        const Eigen::Vector2d along = (R * Eigen::Vector3d(std::cos(a), std::sin(a), 0)).head<2>();
        const Eigen::Vector2d face_h = along.normalized() * (along.dot(h) < 0 ? -1.0 : 1.0);
        const double face_w = std::pow(face->second.sigma, -2);
        h = (w * h + face_w * face_h).normalized();
        w += face_w;
      }
      heading += w * h;
      weight += w;
    }
  if (weight <= 0 || heading.norm() < 1e-9) return std::nullopt;
  return WindowHeading{heading.normalized(), 1.0 / std::sqrt(weight)};
}

std::optional<SlidingWindow::LineVelocity> SlidingWindow::boxLineVelocity(const Track& track) const {
  const std::optional<WindowHeading> window_heading = windowHeading(track);
  const std::optional<SpeedFit> fit = windowMotion(track, window_heading);
  if (!fit) return std::nullopt;
  LineVelocity line;
  line.velocity = fit->velocity;
  const double var_fit = std::max(fit->sigma * fit->sigma, 1e-6);
  line.covariance = var_fit * Eigen::Matrix2d::Identity();
  line.vertical_variance = var_fit;
  if (!window_heading) return line;
  const Eigen::Vector2d& heading = window_heading->direction;
  const double heading_sigma = window_heading->sigma;
  line.velocity = velocityAlongHeading(*fit, heading, heading_sigma);
  // Across the heading the fused variance of the two (velocityAlongHeading's weights).
  const double var_heading = std::pow(fit->velocity.head<2>().norm() * heading_sigma, 2);
  const Eigen::Vector2d across(-heading.y(), heading.x());
  const double var_across = std::max(var_fit * var_heading / (var_fit + var_heading), 1e-6);
  line.covariance = var_fit * heading * heading.transpose() + var_across * across * across.transpose();
  return line;
}

std::vector<VelocityEvidence> SlidingWindow::pointsVelocities(const Track& track, int first_frame) const {
  // The ego's per-frame translation error: the odometry factor's sigma (eq. 8).
  const double ego_sigma = 0.5 * (config_.odometry_sigma[0] + config_.odometry_sigma[1]);
  std::vector<VelocityEvidence> measured;
  for (auto it = track.motions.lower_bound(first_frame); it != track.motions.end(); ++it) {
    const int f = it->first;
    const auto prev = track.observations.find(f - 1);
    const EgoFrame *a = findFrame(f - 1), *b = findFrame(f);
    if (prev == track.observations.end() || !a || !b) continue;
    const double dt = 1e-6 * static_cast<double>(b->utime - a->utime);
    const Eigen::Vector3d p_prev = fromBlock(a->pose->data()) * prev->second.b.translation();
    // It measured the mean velocity over frames f-1..f; the newest frame's velocity is asked for.
    const double age = secondsBetween(f, frames_.back().frame) + 0.5 * dt;
    if (const auto v = registeredVelocity(it->second.M, it->second.information, p_prev, dt, ego_sigma,
                                          config_.vehicle_acceleration * age))
      measured.push_back(*v);
  }
  // Far away: the face's speed along the line of sight over the last pairs, if any.
  if (measured.empty()) {
    const int t = frames_.back().frame;
    std::vector<PairSpeed> pairs;
    for (auto it = track.sight_speeds.lower_bound(t - config_.line_of_sight_pairs + 1); it != track.sight_speeds.end(); ++it)
      pairs.push_back(it->second);
    if (const auto sight = medianPairVelocity(pairs, config_.line_of_sight_min_points)) measured.push_back(*sight);
  }
  // The side's ends measure the motion along the heading, which a side's registration cannot
  // (partial or degenerate): beside the registrations, as independent evidence.
  if (const std::optional<VelocityEvidence> side = sideVelocity(track)) measured.push_back(*side);
  return measured;
}

SlidingWindow::LineVelocity SlidingWindow::youngVehicleVelocity(const Track& track, const LineVelocity& line) const {
  const std::vector<VelocityEvidence> measured = pointsVelocities(track, std::numeric_limits<int>::min());
  if (measured.empty()) return line;
  const FusedVelocity fused = fuseVelocities(line.velocity.head<2>(), line.covariance, measured);
  LineVelocity out = line;
  out.velocity.head<2>() = fused.velocity;
  out.covariance = fused.covariance;
  return out;
}

Eigen::Matrix3d SlidingWindow::stillVelocityCovariance(const Track& track) const {
  // A still track is published with zero velocity; how far that may be off is what the window says
  // of its motion: the evidence's covariance plus its mean squared, the second moment about the
  // published zero. A walker whose boxes cannot yet tell it from standing is still by the test but
  // 1.3 m/s off, which a zero covariance hid from every consumer (and from dlslot-eval's NEES).
  // The walkers' speed prior is left out: it describes walking pedestrians, and a still track is
  // mostly a standing one. With no box in the window (a landmark out of view), the speed the still
  // test lets through.
  const std::optional<LineVelocity> line = boxLineVelocity(track);
  if (!line) return config_.static_max_speed * config_.static_max_speed * Eigen::Matrix3d::Identity();
  const LineVelocity v = isVehicle(track.type) ? youngVehicleVelocity(track, *line) : *line;
  return v.covariance3() + v.velocity * v.velocity.transpose();
}

void SlidingWindow::startTrack(Track& track, int frame) {
  // Static or dynamic from the positions of the trajectory in the window (III-D); the tracker's
  // guess only when the window has too little of it.
  const std::optional<WindowHeading> heading = windowHeading(track);
  const std::optional<SpeedFit> fit = windowMotion(track, heading);
  bool dynamic = track.dynamic_guess;
  if (fit && heading)
    // A vehicle: its speed along its heading, the sideways part being noise (motion_evidence.hpp).
    // Far cars creeping at 1-3 m/s in a queue, 80-105 m away, fitted at 1.4-1.5 sigmas there but
    // not 2 in the plane, were published still for their first 2-4 frames (highway-jam 10).
    dynamic = movesBeyond(std::abs(fit->velocity.head<2>().dot(heading->direction)), fit->sigma,
                          config_.static_max_speed, sigmasOnOneAxis(config_.dynamic_min_sigmas));
  else if (fit)
    dynamic = movesBeyond(fit->speed, fit->sigma, config_.static_max_speed, config_.dynamic_min_sigmas);
  // A vehicle whose points measured its motion (registrations, the line of sight): that motion
  // fused with its boxes' line bounds its speed far more tightly than 3-4 boxes do. Queues' vans
  // and trucks creeping at 1-3 m/s were started static by their boxes and published still for
  // their first 2-9 frames (highway-jam seeds 1, 2 and 7).
  if (!dynamic && isVehicle(track.type) &&
      (!track.motions.empty() || !track.sight_speeds.empty() || !track.side_scans.empty()))
    if (const std::optional<LineVelocity> line = boxLineVelocity(track)) {
      const LineVelocity v = youngVehicleVelocity(track, *line);
      dynamic = movesBeyond(v.velocity.head<2>(), v.covariance, config_.static_max_speed, config_.dynamic_min_sigmas);
    }
  track.model = dynamic ? TrackModel::kDynamic : TrackModel::kStatic;
  if (!dynamic) newBlock(track.landmark, fromBlock(frames_.back().pose->data()) * track.observations.at(frame).b);
}

void SlidingWindow::addTrackObservation(Track& track, int frame) {
  Observation& obs = track.observations.at(frame);
  double* x = findFrame(frame)->pose->data();
  const Pose X = fromBlock(x);
  // The translation sigmas grow with the box's range.
  const double growth = config_.observationNoiseGrowth(obs.b.translation().norm());
  const auto sigmas = [growth](Vector6 sigma) {
    sigma.head<3>() *= growth;
    return sigma;
  };
  const Matrix6 S = sqrtInformation(sigmas(config_.boxSigma(track.type, track.model != TrackModel::kStatic)));
  if (track.model == TrackModel::kStatic) {
    addFactor(LandmarkObservationFactor::Create(obs.b, S), true, {x, track.landmark->data()});
  } else {
    extendChain(track, frame, X * obs.b);
    addFactor(ObservationFactor::Create(obs.b, S), true, {x, track.poses.at(frame)->data()});
    // Its heading from its faces' points (robust: a neighbour's side in its box can turn the fit).
    if (const auto face = track.face_headings.find(frame); face != track.face_headings.end())
      addFactor(FaceHeadingFactor::Create(face->second.yaw, face->second.sigma), true,
                {x, track.poses.at(frame)->data()});
  }
  obs.in_graph = true;
}

void SlidingWindow::extendChain(Track& track, int frame, const Pose& o) {
  if (track.poses.empty()) {
    newBlock(track.poses[frame], o);
    return;
  }
  // Frames the object was not seen in get poses too (interpolated), so the pose changes stay
  // per frame and the object bridges the gap at constant velocity.
  const int last = track.poses.rbegin()->first;
  const Pose o_last = fromBlock(track.poses.rbegin()->second->data());
  for (int f = last + 1; f <= frame; ++f) {
    const Pose o_f = f == frame ? o : interpolate(o_last, o, double(f - last) / double(frame - last));
    double* prev = track.poses.at(f - 1)->data();
    double* cur = newBlock(track.poses[f], o_f);
    double* change = newBlock(track.changes[f - 1], fromBlock(prev).inverse() * o_f);  // eq. 2
    const Eigen::Vector3d displacement = o_f.translation() - fromBlock(prev).translation();
    addFactor(PoseChangeFactor::Create(sqrtInformation(config_.pose_change_sigma)), false, {prev, cur, change});
    if (isVehicle(track.type)) addFactor(VehicleMotionFactor::Create(config_.vehicle_motion_sigma), false, {change});
    if (isVehicle(track.type) && track.changes.size() == 1) startStraight(track, f, change, displacement);
    // The object's points measured how it moved against the sensor between f - 1 and f (robust: a
    // wrong association registers two objects' points).
    const auto m = track.motions.find(f);
    const EgoFrame *ego_prev = findFrame(f - 1), *ego_cur = findFrame(f);
    if (m != track.motions.end() && ego_prev && ego_cur) {
      const RegistrationMeasurement rm =
          registrationMeasurement(m->second.M, m->second.information, m->second.X_prev, m->second.X_cur);
      addFactor(RegistrationFactor::Create(rm.A_meas, rm.sqrt_info), true,
                {ego_prev->pose->data(), ego_cur->pose->data(), prev, change});
    }
    if (track.sight_on_chain) addPairSpeedFactors(track, f);
    auto before = track.changes.find(f - 2);
    if (before != track.changes.end())
      addFactor(ConstantVelocityFactor::Create(sqrtInformation(constantVelocitySigma(track, f, displacement))), false,
                {before->second->data(), change});
    auto before2 = track.changes.find(f - 3);
    if (before != track.changes.end() && before2 != track.changes.end())
      addFactor(ConstantAccelerationFactor::Create(config_.constant_acceleration_sigma), false,
                {before2->second->data(), before->second->data(), change});
  }
  // The faces' speeds go on the chain once it spans the window, and then every pair in the window
  // the young path read: a young chain has too little else to outvote a face that jumps between
  // scans (intersection seed 7: two such pairs took a car's young chain to 12 m/s against its 6,
  // and it then braked to 0.6 against 3; the young path's median of pairs is robust to them), and
  // a chain that took only the pairs after its velocity was first read from it had none of them
  // at that first read.
  if (config_.line_of_sight_chain && !track.sight_on_chain &&
      static_cast<int>(track.changes.size()) >= config_.window_size - 1) {
    track.sight_on_chain = true;
    for (const auto& [g, c] : track.changes) addPairSpeedFactors(track, g + 1);
  }
}

void SlidingWindow::addPairSpeedFactors(const Track& track, int f) {
  // The pairs' speeds between f - 1 and f (robust: 13-31 % of the line-of-sight pairs are over
  // 1 m/s off, line_of_sight.hpp): the face's along the line of sight where no registration
  // measured the motion, the side's ends' along the heading, which a side's registration does not
  // measure (side_ends.hpp).
  const EgoFrame *ego_prev = findFrame(f - 1), *ego_cur = findFrame(f);
  const auto pose = track.poses.find(f - 1);
  const auto change = track.changes.find(f - 1);
  if (!ego_prev || !ego_cur || pose == track.poses.end() || change == track.changes.end()) return;
  const double dt = secondsBetween(f - 1, f);
  const auto add = [&](const PairSpeed& s) {
    if (!countsAlone(s, config_.line_of_sight_min_points)) return;
    addFactor(SightSpeedFactor::Create(Eigen::Vector3d(s.u.x(), s.u.y(), 0.0), s.speed * dt - s.sensor_displacement,
                                       s.sigma * dt),
              true, {ego_prev->pose->data(), ego_cur->pose->data(), pose->second->data(), change->second->data()});
  };
  if (const auto sight = track.sight_speeds.find(f); sight != track.sight_speeds.end() && !track.motions.count(f))
    add(sight->second);
  if (const auto side = track.side_speeds.find(f); side != track.side_speeds.end()) add(side->second);
}

void SlidingWindow::startStraight(const Track& track, int f, double* change, const Eigen::Vector3d& displacement) {
  const double dt = secondsBetween(f - 1, f);
  if (config_.vehicle_acceleration <= 0 || !(dt > 0)) return;
  const double sigma_rz = config_.vehicle_acceleration * dt / vehicleSpeed(track, displacement, dt);
  addFactor(VehicleMotionFactor::StartingStraight(sigma_rz), false, {change});
}

double SlidingWindow::vehicleSpeed(const Track& track, const Eigen::Vector3d& displacement, double dt) const {
  // The track's velocity when it has one, else this frame's displacement. Below 1 m/s a vehicle
  // may turn on the spot as far as the priors that divide by it are concerned.
  const double speed = track.velocity ? track.velocity->head<2>().norm() : displacement.head<2>().norm() / dt;
  return std::max(speed, 1.0);
}

Vector6 SlidingWindow::constantVelocitySigma(const Track& track, int f, const Eigen::Vector3d& displacement) const {
  Vector6 sigma = config_.constant_velocity_sigma;
  const double dt = secondsBetween(f - 1, f);
  if (config_.vehicle_lateral_jerk <= 0 || !isVehicle(track.type) || !(dt > 0)) return sigma;
  // Eq. 11's rz is the change of the per-frame yaw, d(omega)/dt dt^2, and omega = a_lat / v.
  sigma[5] = config_.vehicle_lateral_jerk * dt * dt / vehicleSpeed(track, displacement, dt);
  return sigma;
}

// ---- step 3: a landmark that moves becomes a dynamic object ----

int SlidingWindow::switchMovingLandmarks() {
  int switched = 0;
  for (auto& [id, track] : tracks_) {
    if (track.model != TrackModel::kStatic) continue;
    std::vector<Eigen::Vector3d> positions;
    for (const auto& [f, obs] : track.observations)
      if (obs.in_graph) positions.push_back(fromBlock(findFrame(f)->pose->data()) * obs.b.translation());
    bool moved = leftLandmark(positions, fromBlock(track.landmark->data()).translation(), config_.switch_distance,
                              config_.switch_frames);
    // A walker started still on its first 3-4 boxes is judged again at every frame by its line: it
    // seldom leaves its landmark by switch_distance, as the landmark follows its boxes.
    if (!moved && !isVehicle(track.type) && config_.switch_min_sigmas > 0)
      if (const std::optional<SpeedFit> fit = windowMotion(track, std::nullopt))
        moved = movesBeyond(fit->speed, fit->sigma, config_.static_max_speed, config_.switch_min_sigmas);
    // A still vehicle is judged again at every frame by its points: their registrations of the last
    // frames measure a car pulling away from a stop, or creeping at 1 m/s with its landmark
    // following its boxes, frames before those boxes leave the landmark.
    if (!moved && isVehicle(track.type) && config_.switch_min_sigmas > 0)
      moved = measuredMotion(pointsVelocities(track, frames_.back().frame - config_.line_of_sight_pairs + 1),
                             config_.static_max_speed, config_.switch_min_sigmas);
    if (moved) {
      makeDynamic(track);
      ++switched;
    }
  }
  return switched;
}

void SlidingWindow::makeDynamic(Track& track) {
  // The landmark's observations inside the window are re-added as dynamic observations; what
  // older (marginalized) ones said about the ego poses stays: the landmark is marginalized out
  // of the prior, not dropped.
  double* L = track.landmark->data();
  std::vector<const Factor*> priors;
  for (const Factor& f : factors_)
    if (f.touches(L) && dynamic_cast<const MarginalizationPrior*>(f.cost.get())) priors.push_back(&f);
  std::optional<Factor> prior;
  if (!priors.empty()) prior = marginalizer_.marginalize(priors, {L}, fixed_);
  factors_.erase(std::remove_if(factors_.begin(), factors_.end(), [L](const Factor& f) { return f.touches(L); }),
                 factors_.end());
  if (prior) factors_.push_back(std::move(*prior));
  track.landmark.reset();
  track.model = TrackModel::kDynamic;
  for (auto& [f, obs] : track.observations)
    if (obs.in_graph) addTrackObservation(track, f);
}

// ---- step 4: solve eq. 12 ----

void SlidingWindow::solve(BackendOutput& out) {
  const auto t0 = Clock::now();
  // Separator: the object blocks the prior holds, then the landmarks and the ego poses (the
  // factorization's tail, whose covariances are exact). Groups: each dynamic object's poses
  // and pose changes outside the prior.
  std::unordered_set<const double*> in_prior;
  for (const Factor& f : factors_)
    if (dynamic_cast<const MarginalizationPrior*>(f.cost.get())) in_prior.insert(f.blocks.begin(), f.blocks.end());
  std::vector<double*> separator, tail;
  std::vector<std::vector<double*>> groups;
  for (const auto& [id, track] : tracks_) {
    if (track.landmark) tail.push_back(track.landmark->data());
    // In time order, o_f then c_f: the group's matrix is then banded (WindowSolver).
    std::vector<double*> group;
    for (const auto& [f, o] : track.poses) {
      auto c = track.changes.find(f);
      for (double* b : {o->data(), c == track.changes.end() ? nullptr : c->second->data()})
        if (b) (in_prior.count(b) ? separator : group).push_back(b);
    }
    if (!group.empty()) groups.push_back(std::move(group));
  }
  for (const EgoFrame& f : frames_) tail.push_back(f.pose->data());
  separator.insert(separator.end(), tail.begin(), tail.end());
  std::vector<const Factor*> factors;
  for (const Factor& f : factors_) factors.push_back(&f);
  out.stats.num_blocks = static_cast<int>(liveBlocks().size());
  out.stats.num_factors = static_cast<int>(factors_.size());

  WindowSolver::Options so;
  so.max_iterations = config_.max_iterations;
  so.function_tolerance = config_.function_tolerance;
  so.gradient_tolerance = config_.gradient_tolerance;
  so.parameter_tolerance = config_.parameter_tolerance;
  so.covariance = config_.compute_covariance;
  const auto summary = solver_.solve(factors, separator, groups, fixed_, static_cast<int>(tail.size()), so, &parallel_);
  out.stats.iterations = summary.iterations;
  out.stats.initial_cost = summary.initial_cost;
  out.stats.final_cost = summary.final_cost;
  out.stats.solve_ms = msSince(t0);
  const auto t1 = Clock::now();
  fillTracks(out);
  out.stats.covariance_ms = msSince(t1);
}

void SlidingWindow::fillTracks(BackendOutput& out) {
  const int t = frames_.back().frame;
  auto covariance = [&](const double* block) -> Matrix6 {
    if (!config_.compute_covariance) return Matrix6::Zero();
    return solver_.covariance(block).value_or(Matrix6::Zero());
  };
  out.ego_covariance = covariance(frames_.back().pose->data());
  for (auto& [id, track] : tracks_) {
    if (track.model == TrackModel::kNotInGraph) continue;
    TrackEstimate e;
    e.id = id;
    e.type = track.type;
    e.size = track.size;
    e.dynamic = track.model == TrackModel::kDynamic;
    e.age = t - first_seen_.at(id);
    e.last_seen_frame = track.last_seen;
    e.status = track.last_seen == t ? TrackStatus::Confirmed : TrackStatus::Coasting;
    e.confidence = track.confidence;
    for (const auto& [f, obs] : track.observations) e.num_observations += obs.in_graph;
    const double* block = nullptr;
    std::optional<Matrix6> block_covariance;  // when the velocity's joint covariance gave it
    if (!e.dynamic) {
      block = track.landmark->data();
      e.pose = fromBlock(block);
      if (config_.compute_covariance) e.velocity_covariance = stillVelocityCovariance(track);
    } else {
      const auto& [f_last, o_last] = *track.poses.rbegin();
      block = f_last == t ? o_last->data() : nullptr;
      e.pose = *predictedPose(track);
      if (track.changes.size() >= 2) {
        // Angular velocity from the latest pose change c_f^{f+1} = o_f^-1 o_{f+1} over its time.
        const auto& [f, c_block] = *track.changes.rbegin();
        const double dt = secondsBetween(f, f + 1);
        if (dt > 0) {
          const Eigen::Matrix3d R_f = fromBlock(track.poses.at(f)->data()).linear();
          const Vector6 c = logPose(fromBlock(c_block->data()));
          track.angular_velocity = R_f * c.tail<3>() / dt;
        }
      }
      if (!isVehicle(track.type)) {
        // A pedestrian: the line through its boxes in the window, at every age. Its chain's newest
        // pose change swung 2-30 m/s on walkers the tracker fed a stray box or the chain a wrong
        // turn (intersection seeds 3 and 10: 6 and 18 errors > 3 m/s; none with the line), and the
        // line is better on the tuning seeds 1-5 (pedestrian velocity RMSE 0.308 / 0.442 / 0.657 /
        // 0.489 / 0.474 -> 0.296 / 0.422 / 0.413 / 0.415 / 0.422 m/s). Drawn toward standing by
        // the walkers' speed prior as far as the line is uncertain (a young walker's).
        if (std::optional<LineVelocity> line = boxLineVelocity(track)) {
          const PlanarVelocity v = withSpeedPrior(line->velocity.head<2>(), line->covariance, config_.walker_rms_speed);
          line->velocity.head<2>() = v.velocity;
          line->covariance = v.covariance;
          track.velocity = line->velocity;
          track.velocity_covariance = line->covariance3();
        }
      } else if (static_cast<int>(track.changes.size()) >= config_.window_size - 1) {
        // The linear velocity from the chain (eq. 10-11 and the constant-acceleration factor smooth
        // it) once the chain spans the window: from then on the marginalization prior carries its
        // history beyond the window. A younger chain's pose changes are worse than a line through
        // the window's boxes (tuning runs highway, highway-jam, intersection seed 1, velocity RMSE
        // 0.49 / 0.54 / 0.50 reading the chain from 2 changes on, 0.44 / 0.47 / 0.43 from 9 on;
        // measured with the acceleration factors marginalized, before they were dropped). Reading
        // it only from age 20 on helped the simulated drives by 1-3 % but not the real slice's van
        // (velocity RMSE 0.807 -> 0.824 m/s): not done.
        const auto last = track.poses.rbegin();
        auto first = last;
        for (int i = 0; i < config_.velocity_frames && std::next(first) != track.poses.rend(); ++i) ++first;
        const double span = secondsBetween(first->first, last->first);
        if (span > 0) {
          track.velocity = (fromBlock(last->second->data()).translation() - fromBlock(first->second->data()).translation()) / span;
          track.velocity_from_chain = true;
          // Its covariance from the two poses' joint one; their tangents' translations are the
          // world's (pose_manifold.hpp), so the difference's is C_ll + C_ff - C_lf - C_fl.
          if (config_.compute_covariance)
            if (const auto C = solver_.jointCovariance({first->second->data(), last->second->data()})) {
              track.velocity_covariance = (C->block<3, 3>(0, 0) + C->block<3, 3>(6, 6) - C->block<3, 3>(0, 6) -
                                           C->block<3, 3>(6, 0)) / (span * span);
              if (last->second->data() == block) block_covariance = C->block<6, 6>(6, 6);
            }
        }
      } else if (!track.velocity_from_chain) {
        // Young: the line through its boxes in the window (evidence before initialization
        // included), turned toward their heading for a vehicle. A track whose chain the window
        // has cut short (coasting, or leaving) keeps the velocity its chain last gave. Its points'
        // registrations, when it has any, measure the same motion far better than 2-9 boxes.
        if (const auto line = boxLineVelocity(track)) {
          const LineVelocity v = youngVehicleVelocity(track, *line);
          track.velocity = v.velocity;
          track.velocity_covariance = v.covariance3();
        }
      }
      if (track.velocity) {
        e.velocity = *track.velocity;
        e.velocity_covariance = track.velocity_covariance;
        // A coasting vehicle's chain ends in the frame it was last seen in, and so does the velocity
        // read from it; it may have changed since by vehicle_acceleration x the time (a young
        // track's registered velocities count their age already, pointsVelocities).
        const double unseen_s = secondsBetween(f_last, t);
        if (track.velocity_from_chain && unseen_s > 0)
          e.velocity_covariance.topLeftCorner<2, 2>() +=
              std::pow(config_.vehicle_acceleration * unseen_s, 2) * Eigen::Matrix2d::Identity();
      }
      e.angular_velocity = track.angular_velocity;
      if (track.velocity) track.front = withMotion(track.front, track.velocity->head<2>(), e.pose.linear().col(0).head<2>());
    }
    // alignedBox keeps a track's heading consistent with itself, so a track born from a box turned
    // round heads backwards: a vehicle whose front (its motion, else its detections' majority,
    // track_front.hpp) is the other end is published turned by pi, the same box (velocity and
    // covariance are world-frame and unchanged).
    if (isVehicle(track.type) && turned(track.front)) e.pose.linear() = e.pose.linear() * Eigen::Vector3d(-1, -1, 1).asDiagonal();
    if (block) e.covariance = block_covariance ? *block_covariance : covariance(block);
    // The published box made to cover the object's accumulated points of this frame (a partly
    // seen car's size and centre); the graph keeps its own estimate. Only the points within the
    // fixed margin of its box: the wider margin of a far box's crop (attachObjectPoints) reached
    // the car ahead in a queue, and the box grown over it (highway-jam seed 7: MOTP 0.147 ->
    // 0.176 m with all points).
    if (config_.registration_refine_boxes && registers(track.type) && track.accumulated.frame() == t) {
      Box box;
      box.center = e.pose.translation();
      box.size = e.size;
      box.yaw = yawOf(e.pose.linear());
      const BoxContainment within(box, config_.registration_box_margin);  // the yaw's sine and cosine once
      ObjectPoints own;
      for (const Eigen::Vector3f& p : track.accumulated.points())
        if (within.contains(p.x(), p.y(), p.z())) own.push_back(p);
      const RefinedBox r = refinedBox(e.pose, e.size, own, fromBlock(frames_.back().pose->data()).translation(),
                                      config_.registration.min_points);
      e.pose = r.pose;
      e.size = r.size;
    }
    out.tracks.push_back(std::move(e));
  }
}

// ---- step 5: slide the window ----

SmoothedPose SlidingWindow::slide() {
  EgoFrame& oldest = frames_.front();
  const int s = oldest.frame;
  SmoothedPose smoothed{s, oldest.utime, fromBlock(oldest.pose->data())};
  std::unordered_set<const double*> leaving{oldest.pose->data()};
  std::vector<Track*> left_view;
  for (auto& [id, track] : tracks_) {
    if (track.model == TrackModel::kNotInGraph) continue;
    bool seen_later = false;
    for (auto it = track.observations.upper_bound(s); it != track.observations.end(); ++it) seen_later |= it->second.in_graph;
    if (!seen_later) left_view.push_back(&track);
    if (track.model == TrackModel::kStatic) {
      if (!seen_later) leaving.insert(track.landmark->data());
      continue;
    }
    for (const auto& [f, block] : track.poses)
      if (f <= s || !seen_later) leaving.insert(block->data());
    for (const auto& [f, block] : track.changes)
      if (f <= s || !seen_later) leaving.insert(block->data());
  }
  // Constant-acceleration factors on a leaving pose change: marginalized with it when
  // marginalize_acceleration is set, else dropped. Dropped, the prior holds one pose change of
  // every moving object and eq. 11 alone carries its motion across the slide: a random-walk
  // velocity model, whose newest velocity trails a braking or accelerating object by a steady
  // lag (an alpha-beta filter's (alpha - beta/2)/beta frames; measured 0.2-0.4 s on the
  // simulated traffic, docs/object-motion.md). Marginalized, the prior holds two pose changes
  // per object, i.e. the acceleration, and a constant acceleration is followed without lag.
  // (It used to cost 6x the marginalization: the kept second pose change has no rotation
  // information, the CA factor measures translations, and the singular prior went to an
  // eigen-decomposition; the Marginalizer now factorizes without such directions.)
  auto dropped = [&](const Factor& f) {
    if (!dynamic_cast<const ConstantAccelerationFactor*>(f.cost.get())) return false;
    for (double* b : f.blocks)
      if (leaving.count(b)) return true;
    return false;
  };
  if (!config_.marginalize_acceleration)
    factors_.erase(std::remove_if(factors_.begin(), factors_.end(), dropped), factors_.end());
  marginalizeBlocks(leaving);

  // A walker's leaving box stays in its line for walker_line_span_s (walkers keep their pace
  // longer than the window lasts; the config says how long, measured on KITTI).
  const double newest = 1e-6 * static_cast<double>(frames_.back().utime);
  for (auto& [id, track] : tracks_) {
    if (isVehicle(track.type)) {  // (a track re-labelled a cyclist keeps no walker's boxes)
      track.past_boxes.clear();
      continue;
    }
    if (const auto it = track.observations.find(s); it != track.observations.end())
      track.past_boxes.push_back(
          {1e-6 * static_cast<double>(oldest.utime), smoothed.pose * it->second.b.translation()});
    while (!track.past_boxes.empty() && newest - track.past_boxes.front().t > config_.walker_line_span_s)
      track.past_boxes.pop_front();
  }
  for (auto& [id, track] : tracks_) {
    track.poses.erase(track.poses.begin(), track.poses.upper_bound(s));
    track.changes.erase(track.changes.begin(), track.changes.upper_bound(s));
    track.observations.erase(track.observations.begin(), track.observations.upper_bound(s));
    track.motions.erase(track.motions.begin(), track.motions.upper_bound(s));
    track.sight_speeds.erase(track.sight_speeds.begin(), track.sight_speeds.upper_bound(s));
    track.side_scans.erase(track.side_scans.begin(), track.side_scans.upper_bound(s));
    track.side_speeds.erase(track.side_speeds.begin(), track.side_speeds.upper_bound(s));
    track.face_headings.erase(track.face_headings.begin(), track.face_headings.upper_bound(s));
  }
  for (Track* track : left_view) {
    track->model = TrackModel::kNotInGraph;
    track->landmark.reset();
    track->poses.clear();
    track->changes.clear();
    track->velocity.reset();
    track->velocity_from_chain = false;
    track->sight_on_chain = false;
    track->past_boxes.clear();
  }
  // Tracks with nothing left in the window are forgotten (first_seen_ keeps their age).
  for (auto it = tracks_.begin(); it != tracks_.end();)
    it = it->second.observations.empty() && it->second.model == TrackModel::kNotInGraph ? tracks_.erase(it) : std::next(it);
  fixed_.erase(oldest.pose->data());
  frames_.pop_front();
  return smoothed;
}

void SlidingWindow::marginalizeBlocks(const std::unordered_set<const double*>& leaving) {
  std::vector<const Factor*> touching;
  for (const Factor& f : factors_)
    for (double* b : f.blocks)
      if (leaving.count(b)) {
        touching.push_back(&f);
        break;
      }
  if (touching.empty()) return;
  std::optional<Factor> prior = marginalizer_.marginalize(touching, leaving, fixed_);
  factors_.erase(std::remove_if(factors_.begin(), factors_.end(),
                                [&](const Factor& f) {
                                  for (double* b : f.blocks)
                                    if (leaving.count(b)) return true;
                                  return false;
                                }),
                 factors_.end());
  if (prior) factors_.push_back(std::move(*prior));
}

// ---- helpers ----

void SlidingWindow::addFactor(ceres::CostFunction* cost, bool robust, std::vector<double*> blocks) {
  factors_.push_back(Factor{std::shared_ptr<ceres::CostFunction>(cost), robust ? observation_loss_ : nullptr,
                            std::move(blocks)});
}

double* SlidingWindow::newBlock(Block& slot, const Pose& value) {
  slot = std::make_unique<Vector7>(toBlock(value));
  return slot->data();
}

bool SlidingWindow::isVehicle(const std::string& type) const {
  return std::find(config_.vehicle_types.begin(), config_.vehicle_types.end(), type) != config_.vehicle_types.end();
}

const SlidingWindow::EgoFrame* SlidingWindow::findFrame(int frame) const {
  for (const EgoFrame& f : frames_)
    if (f.frame == frame) return &f;
  return nullptr;
}

double SlidingWindow::secondsBetween(int f0, int f1) const {
  const EgoFrame *a = findFrame(f0), *b = findFrame(f1);
  return a && b ? 1e-6 * static_cast<double>(b->utime - a->utime) : 0.0;
}

Pose SlidingWindow::alignedBox(const Track& track, const Pose& X, const Box& box) const {
  // A box and the box turned by pi are the same box; detectors flip headings. Keep the heading
  // closest to what the track already has: its newest pose, not extrapolated by its yaw rate (a
  // young chain's yaw rate comes from two or three boxes; a cyclist's scatter by 0.3 rad, and
  // two frames of such a rate turned its next, right box round: intersection seed 2); else its
  // last observation.
  std::optional<double> reference;
  if (track.model == TrackModel::kStatic) {
    reference = yawOf(fromBlock(track.landmark->data()).linear());
  } else if (track.model == TrackModel::kDynamic && !track.poses.empty()) {
    reference = yawOf(fromBlock(track.poses.rbegin()->second->data()).linear());
  } else if (!track.observations.empty()) {
    const auto& [f, obs] = *track.observations.rbegin();
    if (const EgoFrame* ego = findFrame(f)) reference = yawOf(fromBlock(ego->pose->data()).linear() * obs.b.linear());
  }
  Box b = box;
  if (reference && !headingsAgree(yawOf(X.linear() * b.pose().linear()), *reference))
    b.yaw = wrapAngle(b.yaw + M_PI);
  return b.pose();
}

std::optional<Pose> SlidingWindow::predictedPose(const Track& track) const {
  if (track.model == TrackModel::kStatic) return fromBlock(track.landmark->data());
  if (track.model != TrackModel::kDynamic) return std::nullopt;
  const auto& [f_last, o_last] = *track.poses.rbegin();
  const int ahead = frames_.back().frame - f_last;
  if (ahead <= 0 || track.changes.empty()) return fromBlock(o_last->data());
  return fromBlock(o_last->data()) * power(fromBlock(track.changes.rbegin()->second->data()), ahead);
}

std::vector<double*> SlidingWindow::liveBlocks() const {
  std::vector<double*> blocks;
  for (const EgoFrame& f : frames_) blocks.push_back(f.pose->data());
  for (const auto& [id, track] : tracks_) {
    if (track.landmark) blocks.push_back(track.landmark->data());
    for (const auto& [f, b] : track.poses) blocks.push_back(b->data());
    for (const auto& [f, b] : track.changes) blocks.push_back(b->data());
  }
  return blocks;
}

std::vector<int> SlidingWindow::windowFrames() const {
  std::vector<int> out;
  for (const EgoFrame& f : frames_) out.push_back(f.frame);
  return out;
}

std::optional<Pose> SlidingWindow::egoPose(int frame) const {
  const EgoFrame* f = findFrame(frame);
  if (!f) return std::nullopt;
  return fromBlock(f->pose->data());
}

std::optional<Pose> SlidingWindow::objectPose(int track_id, int frame) const {
  auto it = tracks_.find(track_id);
  if (it == tracks_.end()) return std::nullopt;
  const Track& track = it->second;
  if (track.model == TrackModel::kStatic) return fromBlock(track.landmark->data());
  auto p = track.poses.find(frame);
  if (p == track.poses.end()) return std::nullopt;
  return fromBlock(p->second->data());
}

SlidingWindow::TrackModel SlidingWindow::trackModel(int track_id) const {
  auto it = tracks_.find(track_id);
  return it == tracks_.end() ? TrackModel::kNotInGraph : it->second.model;
}

int SlidingWindow::priorDimension() const {
  int dim = 0;
  for (const Factor& f : factors_)
    if (const auto* p = dynamic_cast<const MarginalizationPrior*>(f.cost.get())) dim += 6 * p->numBlocks();
  return dim;
}

}  // namespace dlslot::backend
