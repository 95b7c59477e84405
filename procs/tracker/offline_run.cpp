#include "offline_run.hpp"

#include <chrono>
#include <stdexcept>

namespace dlslot::tracker {

OfflineResult associateSequence(const kitti::SequenceReader& reader, const std::vector<Pose>& ego_poses,
                                const AssociatorConfig& config, bool initialized_only) {
  if (static_cast<int>(ego_poses.size()) < reader.size())
    throw std::invalid_argument("ego poses: " + std::to_string(ego_poses.size()) + " for " +
                                std::to_string(reader.size()) + " frames");
  TrajectoryAssociator associator(config);
  OfflineResult out;
  int max_id = -1;
  for (int i = 0; i < reader.size(); ++i) {
    const Frame frame = reader.read(i);
    const auto tic = std::chrono::steady_clock::now();
    const FrameAssociations r = associator.associate(frame.index, frame.utime * 1e-6, ego_poses[i], frame.detections);
    out.association_ms.add(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - tic).count());
    for (const Association& a : r.associations) {
      ++out.detections;
      out.initialized += a.initialized;
      max_id = std::max(max_id, a.track_id);
      if (initialized_only && !a.initialized) continue;
      kitti::LabelRow row;
      row.frame = frame.index;
      row.track_id = a.track_id;
      row.type = a.box_lidar.type;
      row.alpha = -10;  // the devkit's "unknown": no image observation angle from a 3D detector
      row.box = kitti::lidarToCamera(a.box_lidar, reader.calib());
      row.score = a.box_lidar.score;
      out.tracks.push_back(row);
    }
  }
  out.trajectories = max_id + 1;
  return out;
}

}  // namespace dlslot::tracker
