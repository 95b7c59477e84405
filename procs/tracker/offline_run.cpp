#include "offline_run.hpp"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <set>
#include <stdexcept>

#include "dlslot/input_error.hpp"
#include "track_evidence.hpp"

namespace dlslot::tracker {

std::vector<Pose> egoPosesFor(const kitti::SequenceReader& reader, const std::string& sequence, const std::string& poses,
                              std::string* source) {
  namespace fs = std::filesystem;
  std::vector<Pose> out;
  if (!poses.empty()) {
    const std::string file = fs::is_directory(poses) ? (fs::path(poses) / (sequence + ".txt")).string() : poses;
    if (fs::exists(file)) {
      out = kitti::readPoses(file);
      if (static_cast<int>(out.size()) < reader.size())
        throw InputError(file, 0, "has " + std::to_string(out.size()) + " poses, expected one per frame (" +
                                      std::to_string(reader.size()) + ")");
      *source = "ego poses from " + file;
      return out;
    }
    if (!fs::is_directory(poses)) throw InputError(file, 0, "ego pose file missing");
  }
  if (reader.hasGroundTruthPoses()) {
    *source = "ego poses from the sequence's ground truth";
    return reader.groundTruthPoses();
  }
  *source = "no ego poses for sequence " + sequence + ": identity (tracking in the sensor frame)";
  return std::vector<Pose>(reader.size(), Pose::Identity());
}

OfflineResult associateSequence(const kitti::SequenceReader& reader, const std::vector<Pose>& ego_poses,
                                const AssociatorConfig& config, TrackOutput output, bool all_around) {
  if (static_cast<int>(ego_poses.size()) < reader.size())
    throw std::invalid_argument("ego poses: " + std::to_string(ego_poses.size()) + " for " +
                                std::to_string(reader.size()) + " frames");
  // Speeds over ground need ego poses: with none (every pose the identity, tracking in the sensor
  // frame) a parked object moves at the ego's speed, so the class's speed limits cannot be judged.
  AssociatorConfig cfg = config;
  MotionEvidence motion;
  motion.ego_poses_known = true;
  motion.moved_m = config.dynamic_displacement_m;
  if (std::all_of(ego_poses.begin(), ego_poses.begin() + reader.size(),
                  [](const Pose& X) { return X.matrix().isIdentity(0.0); })) {
    cfg.plausibility.clear();
    motion.ego_poses_known = false;
  }
  TrajectoryAssociator associator(cfg);
  OfflineResult out;
  auto write = [&](int frame, const Box& box) {
    kitti::LabelRow row = kitti::unprojectedRow(frame, box, reader.calib());
    if (auto projected = kitti::resultRow(row, reader.calib())) {
      out.tracks.push_back(std::move(*projected));
      return;
    }
    ++out.outside_image;
    if (all_around) out.tracks.push_back(std::move(row));
  };
  int max_id = -1;
  std::map<int, TrackEvidence> evidence;
  std::map<int, const ClassPolicy*> policy_of;
  std::map<int, std::string> final_type;  // tracks re-labelled by their class's plausibility
  std::set<int> suppressed;               // tracks suppressed by it
  for (int i = 0; i < reader.size(); ++i) {
    const Frame frame = reader.read(i);
    const auto tic = std::chrono::steady_clock::now();
    const FrameAssociations r = associator.associate(frame.index, frame.utime * 1e-6, ego_poses[i], frame.detections);
    out.association_ms.add(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - tic).count());
    out.detections += static_cast<int>(frame.detections.size());
    out.skipped.untracked_type += r.skipped.untracked_type;
    out.skipped.below_score += r.skipped.below_score;
    out.skipped.duplicate += r.skipped.duplicate;
    out.class_decisions += r.class_decisions;
    for (const Association& a : r.associations) {
      ++out.associated;
      max_id = std::max(max_id, a.track_id);
      evidence[a.track_id].add(frame.index, a.box_lidar.score, a.box_world.center, frame.utime * 1e-6);
      policy_of.emplace(a.track_id, policyFor(config.classes, a.box_lidar.type));
      if (a.relabelled) final_type[a.track_id] = a.box_lidar.type;
      const bool confirmed = a.status == TrackStatus::Confirmed;
      out.confirmed += confirmed;
      if (a.suppressed) {
        suppressed.insert(a.track_id);
        ++out.suppressed_rows;
        continue;
      }
      if (output == TrackOutput::Confirmed && !confirmed) continue;
      Box box = a.box_lidar;
      box.id = a.track_id;
      box.score = a.confidence;
      write(frame.index, box);
    }
    for (const CoastingTrack& c : r.coasting) {
      ++out.coasting;
      write(frame.index, c.box_lidar);
    }
  }
  out.trajectories = max_id + 1;
  // A results file reports each track under the class its whole history decided, as it reports
  // one score for it (below): the rows written before the window could judge (its first 0.5 s)
  // take the decision too. A live consumer only gets it from the decision on.
  const auto before = out.tracks.size();
  out.tracks.erase(std::remove_if(out.tracks.begin(), out.tracks.end(),
                                  [&](const kitti::LabelRow& row) { return suppressed.count(row.track_id) > 0; }),
                   out.tracks.end());
  out.suppressed_rows += static_cast<int>(before - out.tracks.size());
  for (kitti::LabelRow& row : out.tracks)
    if (const auto t = final_type.find(row.track_id); t != final_type.end()) row.type = t->second;
  // The score column: each track's evidence over its life (track_evidence.hpp).
  writeTrackScores(out.tracks, evidence, policy_of, motion);
  return out;
}

}  // namespace dlslot::tracker
