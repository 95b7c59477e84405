// One simulated drive, frame by frame: the world and everyone's motion are made up front from the
// scenario and its seed; each frame is a scan plus its labels and detections.
#pragma once

#include <memory>
#include <vector>

#include "dlslot/kitti.hpp"
#include "sensor.hpp"
#include "traffic.hpp"
#include "world.hpp"

namespace dlslot::sim {

class Simulation {
 public:
  explicit Simulation(const Scenario& scenario);  // scenario.frames frames from scenario.seed

  struct FrameData {
    Scan scan;
    ScanInput input;                          // what was scanned (map frame)
    std::vector<kitti::LabelRow> labels;      // label_02 rows
    std::vector<kitti::LabelRow> detections;  // detector rows (with score)
  };
  // Frames must be made in order (track ids are given at an object's first labelled frame).
  FrameData frame(int index, int threads = 1);

  const Scenario& scenario() const { return scenario_; }
  const World& world() const { return world_; }
  const Motion& motion() const { return motion_; }
  const kitti::Calib& calib() const { return calib_; }
  // Ground-truth ego poses T_world_lidar, world = the first scan's lidar frame.
  std::vector<Pose> lidarPoses() const;

 private:
  Scenario scenario_;
  World world_;
  Motion motion_;
  kitti::Calib calib_;
  std::vector<bool> ghosts_;
  std::vector<int> track_id_;  // per agent, -1 until first labelled
  int next_track_id_ = 0;
  int next_frame_ = 0;
  std::vector<BeamError> beam_errors_;  // the sensor's calibration residuals (one per seed)
};

}  // namespace dlslot::sim
