#include "simulation.hpp"

#include <algorithm>
#include <stdexcept>

#include "calib.hpp"
#include "detections.hpp"
#include "labels.hpp"

namespace dlslot::sim {

Simulation::Simulation(const Scenario& scenario)
    : scenario_(scenario),
      world_(buildWorld(scenario_)),
      motion_(simulateMotion(scenario_, world_)),
      calib_(kittiCalib()),
      ghosts_(chooseGhosts(world_, scenario_.detector, streamKey({scenario_.seed, 5}))),
      track_id_(motion_.agents.size(), -1),
      beam_errors_(beamErrors(scenario_.sensor, streamKey({scenario_.seed, 8}))) {}

std::vector<Pose> Simulation::lidarPoses() const {
  std::vector<Pose> poses;
  const Pose T_world_map = motion_.ego.front().inverse();
  for (const Pose& T : motion_.ego) poses.push_back(T_world_map * T);
  return poses;
}

Simulation::FrameData Simulation::frame(int index, int threads) {
  if (index != next_frame_) throw std::logic_error("Simulation::frame: frames must be made in order");
  ++next_frame_;
  FrameData fd;
  ScanInput& in = fd.input;
  in.world = &world_;
  in.T_map_lidar = motion_.ego[index];
  const int frames = static_cast<int>(motion_.ego.size());
  in.period_s = scenario_.frame_period_s;
  in.ego = sweepMotion(index > 0 ? &motion_.ego[index - 1] : nullptr, in.T_map_lidar,
                       index + 1 < frames ? &motion_.ego[index + 1] : nullptr, in.period_s);
  in.beam_errors = beam_errors_;
  in.key = streamKey({scenario_.seed, 6, static_cast<uint64_t>(index)});
  const Pose T_lidar_map = in.T_map_lidar.inverse();
  // Objects within the lidar's range (with a margin for their size) take part in this frame.
  std::vector<int> agent_of;
  for (size_t i = 0; i < motion_.agents.size(); ++i) {
    const Box b = agentBox(motion_.agents[i], index, *world_.ground);
    if ((b.center - in.T_map_lidar.translation()).head<2>().norm() > scenario_.sensor.max_range_m + 10.0) continue;
    agentSolids(motion_.agents[i], static_cast<int>(agent_of.size()), index, *world_.ground, in.object_solids);
    in.object_boxes.push_back(b);
    // Its velocity over this frame's sweep (central difference; objects turn little in 50 ms).
    const int lo = std::max(0, index - 1), hi = std::min(frames - 1, index + 1);
    in.object_velocity.push_back(hi > lo ? Eigen::Vector3d((agentBox(motion_.agents[i], hi, *world_.ground).center -
                                                            agentBox(motion_.agents[i], lo, *world_.ground).center) /
                                                           ((hi - lo) * in.period_s))
                                         : Eigen::Vector3d::Zero());
    agent_of.push_back(static_cast<int>(i));
  }
  fd.scan = scan(scenario_.sensor, in, threads);

  std::vector<DetectorTarget> targets;
  for (size_t k = 0; k < agent_of.size(); ++k) {
    Box box = in.object_boxes[k].transformed(T_lidar_map);
    if (box.center.head<2>().norm() > scenario_.sensor.max_range_m) continue;
    const ObjectView& view = fd.scan.views[k];
    int& id = track_id_[agent_of[k]];
    const bool dontcare = view.points < scenario_.labels.min_points;
    if (!dontcare && id < 0) id = next_track_id_++;
    // DontCare rows keep the real 3D box so an evaluator can ignore matches there in bird's-eye view.
    fd.labels.push_back(
        labelRow(index, dontcare ? -1 : id, dontcare ? "DontCare" : box.type, box, calib_, occlusionLevel(view)));
    Eigen::Vector2d drift = Eigen::Vector2d::Zero();
    if (scenario_.detector.drift_m > 0 || scenario_.detector.drift_per_m > 0)
      drift = driftProcess(streamKey({scenario_.seed, 8, static_cast<uint64_t>(agent_of[k])}), index * in.period_s,
                           {scenario_.detector.drift_time_s, scenario_.detector.drift_across_time_s});
    targets.push_back({box, id, view.points, drift});
  }
  Rng rng(streamKey({scenario_.seed, 7, static_cast<uint64_t>(index)}));
  fd.detections = detect(index, targets, fd.scan, world_, ghosts_, in.T_map_lidar, scenario_.detector, calib_, rng);
  return fd;
}

}  // namespace dlslot::sim
