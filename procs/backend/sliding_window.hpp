// The sliding-window estimator of DL-SLOT (paper III-C, III-D, eq. 8-12): the ego poses X of
// the last k frames, each initialized object either as one static landmark pose or, when it
// moves, as a pose per frame o plus pose-change vertices c (eq. 2), all solved together with
// Ceres. Per frame:
//   1. add X_t, predicted from X_{t-1} and the odometry's T (eq. 8 factor);
//   2. add the frame's observations: O_init get observation factors (eq. 9 / landmark), O_aso
//      pose-change factors (eq. 10), O_cons constant-velocity factors (eq. 11);
//   3. turn landmarks that started to move into dynamic objects;
//   4. solve eq. 12 (WindowSolver: Levenberg-Marquardt with a per-object Schur complement);
//   5. when the window is full, marginalize the oldest frame (its ego pose, object poses and
//      pose changes, and the objects that left the view) into the prior.
#pragma once

#include <deque>
#include <map>
#include <memory>
#include <unordered_set>
#include <vector>

#include "backend/backend_config.hpp"
#include "backend/backend_types.hpp"
#include "backend/face_heading.hpp"
#include "backend/factor.hpp"
#include "backend/line_of_sight.hpp"
#include "backend/marginalizer.hpp"
#include "backend/motion_evidence.hpp"
#include "backend/object_model.hpp"
#include "backend/pose_manifold.hpp"
#include "backend/registered_velocity.hpp"
#include "backend/side_ends.hpp"
#include "backend/track_front.hpp"
#include "backend/window_solver.hpp"

namespace dlslot::backend {

class SlidingWindow {
 public:
  explicit SlidingWindow(BackendConfig config);
  ~SlidingWindow();

  // Handles one frame; frames must come in increasing order (std::invalid_argument otherwise).
  BackendOutput process(const BackendInput& input);

  enum class TrackModel { kNotInGraph, kStatic, kDynamic };

  // Current estimates, for tests and tools.
  const BackendConfig& config() const { return config_; }
  std::vector<int> windowFrames() const;
  std::optional<Pose> egoPose(int frame) const;
  // A static object's landmark, or a dynamic object's pose at `frame` (when in the window).
  std::optional<Pose> objectPose(int track_id, int frame) const;
  TrackModel trackModel(int track_id) const;
  int priorDimension() const;

 private:
  using Block = std::unique_ptr<Vector7>;
  struct EgoFrame {
    int frame = 0;
    int64_t utime = 0;
    Block pose;
  };
  struct Observation {
    Pose b = Pose::Identity();  // T_lidar_object with the yaw aligned to the track
    bool in_graph = false;      // initialized, so it has a factor (eq. 12's O_init)
  };
  struct Track {
    int id = -1;
    std::string type;
    Eigen::Vector3d size = Eigen::Vector3d::Zero();
    int size_samples = 0;
    int last_seen = -1;
    bool dynamic_guess = false;
    double confidence = 1.0;  // the tracker's lifecycle confidence at the latest detection
    TrackModel model = TrackModel::kNotInGraph;
    Block landmark;                 // static: one pose for the whole window
    std::map<int, Block> poses;     // dynamic: frame -> o_frame
    std::map<int, Block> changes;   // dynamic: frame f -> c_f^{f+1}
    std::map<int, Observation> observations;  // frames in the window
    // A walker's boxes that left the window (world, the ego pose as estimated when they left),
    // within walker_line_span_s of the newest frame.
    std::deque<TimedPosition> past_boxes;
    // The motion last estimated (world frame): kept while the window holds too little of the
    // chain to estimate it again (coasting, or about to leave).
    std::optional<Eigen::Vector3d> velocity;
    Eigen::Matrix3d velocity_covariance = Eigen::Matrix3d::Zero();  // of `velocity`, (m/s)^2
    bool velocity_from_chain = false;
    bool sight_on_chain = false;  // its faces' speeds are factors on its chain (extendChain)
    TrackFront front;  // which end its boxes' heading points to (track_front.hpp)
    // Per-object registration: the object's accumulated points (its model, world frame of its
    // latest scan) and the same prepared as the next frame's source (the latest scan alone when
    // registration_model_frames is 1), and the motions measured between consecutive scans
    // (frame t -> M of t-1 -> t, world frame), each with the ego poses that put the two scans'
    // points into the world (points_ego: those of the kept points).
    ObjectModel accumulated;
    std::shared_ptr<const PreparedObject> points;
    int points_frame = -1;
    Pose points_ego = Pose::Identity();
    struct Motion {
      Pose M = Pose::Identity();
      Matrix6 information = Matrix6::Zero();
      Pose X_prev = Pose::Identity(), X_cur = Pose::Identity();
    };
    std::map<int, Motion> motions;
    // The face along the line of sight in its last scans that showed one (per frame: its points in
    // the world, the direction and the face's range along it), and each scan pair's speed along it
    // (frame t -> t-1 to t; line_of_sight.hpp).
    struct SightFace {
      std::shared_ptr<const ObjectPoints> points;
      Eigen::Vector3d u = Eigen::Vector3d::UnitX();
      double range = 0;
      Eigen::Vector3d sensor = Eigen::Vector3d::Zero();  // the ego position its points were put in the world with
    };
    std::map<int, SightFace> sight_faces;
    std::map<int, PairSpeed> sight_speeds;
    // The scans whose box showed its side: its points (world), the box's heading d (world), one
    // end's standard deviation, which ends (along d) the scan saw and the ego position the points
    // were put in the world with (side_ends.hpp).
    struct SideScanPoints {
      std::shared_ptr<const ObjectPoints> points;
      Eigen::Vector3d d = Eigen::Vector3d::UnitX();
      double end_sigma = 0;
      EndsSeen seen;
      Eigen::Vector3d sensor = Eigen::Vector3d::Zero();
      Eigen::Vector3d box_center = Eigen::Vector3d::Zero();  // world
      double box_sigma = 0;  // of the box's position at its range
    };
    std::map<int, SideScanPoints> side_scans;
    std::map<int, PairSpeed> side_speeds;  // each side scan pair's (frame t -> t-1 to t), measured at t
    // A vehicle's heading from its faces' points, per scan (face_heading.hpp; yaw in the scan's axes).
    std::map<int, FaceHeading> face_headings;
    Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();
  };

  void addEgoFrame(const BackendInput& in, BackendOutput& out);
  // The objects' view of the ego's translation since the previous frame, and the test of the
  // odometry factor's (delta, sqrt information S) against it (odometry_consistency.hpp).
  OdometryCheck checkOdometryFactor(const BackendInput& in, const Pose& delta, const Matrix6& S) const;
  void addObservations(const BackendInput& in, BackendOutput& out);
  void startTrack(Track& track, int frame);
  // Registers the object's points of this frame to its model of the previous ones (or to the
  // previous scan alone, registration_model_frames 1), when it has both, and takes them into it.
  void registerPoints(Track& track, const ObservationInput& obs, int frame, const Pose& X, BackendOutput& out);
  bool registers(const std::string& type) const;
  // Appends the moving vehicles the detector missed in this frame (none of the observations),
  // each with its box where its chain predicts it (lidar frame of the ego pose X).
  void addMissedVehicles(std::vector<ObservationInput>& observations, int frame, const Pose& X) const;
  // The face's range along the line of sight in this scan (world points) and, when the scan
  // before had one, the pair's speed along it (line_of_sight.hpp); true when it measured a pair.
  bool measureLineOfSight(Track& track, const ObjectPoints& world, const Box& box, int frame, const Pose& X,
                          double dt) const;
  // Each kept pair of the face's scans judged by the line through them all (faceSamplesOnLine),
  // this frame's scan the newest.
  void judgeFacePairs(Track& track, int frame) const;
  // This scan's points when its box shows the side (side_ends.hpp) and, when the scan before did
  // too and the pair counts, the pair's speed; true when it measured a pair.
  bool measureSideEnds(Track& track, const ObjectPoints& world, const ObservationInput& obs, int frame, const Pose& X) const;
  // The side's ends' speed along the heading of scan f0 over f0 -> f1, if both show the side and
  // the pair counts (sidePairSpeed).
  std::optional<PairSpeed> sidePair(const Track& track, int f0, int f1) const;
  // A side scan's ends along u and those that count (endsThatCount, named along u).
  std::optional<SideView> sideView(const Track& track, const Track::SideScanPoints& scan, const Eigen::Vector3d& u) const;
  // The line through the ends that count of the window's side scans along the newest one's heading
  // (sideLine), as a velocity at the newest frame: its variance grown by vehicle_acceleration over
  // the time from the scans' mean.
  std::optional<VelocityEvidence> sideVelocity(const Track& track) const;
  // The velocity of the line through the track's boxes in the window (windowMotion), for a
  // vehicle turned toward the mean heading of its boxes (velocityAlongHeading): a young
  // vehicle's, and a pedestrian's at every age.
  struct LineVelocity {
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
    Eigen::Matrix2d covariance = Eigen::Matrix2d::Identity();  // bird's-eye
    double vertical_variance = 1.0;  // of the velocity's upward part
    Eigen::Matrix3d covariance3() const {
      Eigen::Matrix3d c = Eigen::Matrix3d::Zero();
      c.topLeftCorner<2, 2>() = covariance;
      c(2, 2) = vertical_variance;
      return c;
    }
  };
  std::optional<LineVelocity> boxLineVelocity(const Track& track) const;
  // A young vehicle's line velocity fused with the velocities its registrations in the window
  // measured (registered_velocity.hpp); without registrations, with its speed along the line of
  // sight over its last scan pairs (line_of_sight.hpp); else the line as it is.
  LineVelocity youngVehicleVelocity(const Track& track, const LineVelocity& line) const;
  // The covariance of a still track's published (zero) velocity about the truth.
  Eigen::Matrix3d stillVelocityCovariance(const Track& track) const;
  // The velocities over ground its points measured: its registrations from first_frame on
  // (registered_velocity.hpp), else its face's speed along the line of sight over the last pairs.
  std::vector<VelocityEvidence> pointsVelocities(const Track& track, int first_frame) const;
  // A vehicle's bird's-eye heading over the window and its standard deviation (rad): the mean of
  // its boxes' and its faces' headings (face_heading.hpp), each weighted by its inverse variance;
  // none for other classes.
  struct WindowHeading {
    Eigen::Vector2d direction;
    double sigma = 0;
  };
  std::optional<WindowHeading> windowHeading(const Track& track) const;
  // The least-squares motion of the track's observed positions in the window (world frame),
  // boxes of another object left out (with a vehicle's heading, also those that moved across it).
  std::optional<SpeedFit> windowMotion(const Track& track, const std::optional<WindowHeading>& heading) const;
  void addTrackObservation(Track& track, int frame);
  void extendChain(Track& track, int frame, const Pose& o);
  // The pairs' speeds over f - 1 -> f (the face's along the line of sight, the side's ends' along
  // the heading) as factors on the chain, those of enough points, when its poses and the ego's
  // for both frames are in the window.
  void addPairSpeedFactors(const Track& track, int f);
  // The prior that starts a vehicle's chain straight on its first pose change c_{f-1}^f, which
  // moved it by `displacement` (world), at the track's speed (vehicle_motion_factor.hpp).
  void startStraight(const Track& track, int f, double* change, const Eigen::Vector3d& displacement);
  // A vehicle's speed for the priors above (m/s, at least 1).
  double vehicleSpeed(const Track& track, const Eigen::Vector3d& displacement, double dt) const;
  // Eq. 11's sigmas for the pose change c_{f-1}^f, which moved the track by `displacement` (world):
  // a vehicle's rz from vehicle_lateral_jerk at its speed, the rest constant_velocity_sigma.
  Vector6 constantVelocitySigma(const Track& track, int f, const Eigen::Vector3d& displacement) const;
  int switchMovingLandmarks();
  void makeDynamic(Track& track);
  void solve(BackendOutput& out);
  void fillTracks(BackendOutput& out);
  SmoothedPose slide();

  void addFactor(ceres::CostFunction* cost, bool robust, std::vector<double*> blocks);
  // Marginalizes `leaving` with every factor touching it and replaces those by the prior.
  void marginalizeBlocks(const std::unordered_set<const double*>& leaving);
  double* newBlock(Block& slot, const Pose& value);
  const EgoFrame* findFrame(int frame) const;
  // Seconds from window frame f0 to f1; 0 when either has left the window.
  double secondsBetween(int f0, int f1) const;
  bool isVehicle(const std::string& type) const;
  Pose alignedBox(const Track& track, const Pose& X, const Box& box) const;
  std::optional<Pose> predictedPose(const Track& track) const;
  std::vector<double*> liveBlocks() const;

  BackendConfig config_;
  ParallelFor parallel_;
  Marginalizer marginalizer_;
  WindowSolver solver_;
  std::shared_ptr<ceres::LossFunction> observation_loss_;
  std::deque<EgoFrame> frames_;
  std::map<int, Track> tracks_;
  std::map<int, int> first_seen_;  // track id -> frame it was first seen (for its age)
  std::vector<Factor> factors_;
  std::unordered_set<const double*> fixed_;  // ego poses held at the odometry's (two-stage)
  Pose last_delta_ = Pose::Identity();       // for a frame without odometry (constant velocity)
  int last_frame_ = -1;
};

}  // namespace dlslot::backend
