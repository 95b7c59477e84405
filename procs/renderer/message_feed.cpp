#include "message_feed.hpp"

#include <algorithm>
#include <cmath>

#include "dlslot/convert.hpp"

namespace dlslot::renderer {
namespace {

bool finite(const pose_t& p) {
  for (double v : p.position)
    if (!std::isfinite(v)) return false;
  for (double v : p.orientation)
    if (!std::isfinite(v)) return false;
  return true;
}

ModuleTiming timing(const std::string& module, const std::vector<stage_timing_t>& stages) {
  return ModuleTiming{module, fromMsg(stages)};
}

}  // namespace

MessageFeed::MessageFeed(RunState& state, ProcessStatus& status, Channels channels)
    : state_(state), status_(status), channels_(std::move(channels)) {}

bool MessageFeed::validFrame(const std::string& channel, int frame) {
  if (frame >= 0) return true;
  status_.error(channel + ": negative frame index " + std::to_string(frame) + " (message skipped)");
  return false;
}

std::vector<Box> MessageFeed::boxes(const std::string& channel, const std::vector<box_t>& in) {
  std::vector<Box> out;
  for (const box_t& b : in) {
    if (isValid(b))
      out.push_back(fromMsg(b));
    else
      status_.count("invalid_boxes_" + channel);
  }
  return out;
}

void MessageFeed::late(bool accepted, const std::string& channel) {
  if (!accepted) status_.count("late_" + channel);
}

void MessageFeed::onScan(const point_cloud_t& m) {
  if (!validFrame(channels_.scan, m.frame)) return;
  late(state_.addScan(m.frame, m.utime, fromMsg(m)), channels_.scan);
}

void MessageFeed::onDetections(const detections_t& m) {
  if (!validFrame(channels_.detections, m.frame)) return;
  late(state_.addDetections(m.frame, m.utime, boxes(channels_.detections, m.boxes)), channels_.detections);
}

void MessageFeed::onGroundTruth(const ground_truth_t& m) {
  if (!validFrame(channels_.ground_truth, m.frame)) return;
  std::optional<Pose> pose;
  if (m.has_pose && finite(m.pose))
    pose = fromMsg(m.pose);
  else if (m.has_pose)
    status_.error(channels_.ground_truth + ": non-finite pose at frame " + std::to_string(m.frame));
  late(state_.addGroundTruth(m.frame, m.utime, pose, boxes(channels_.ground_truth, m.boxes)), channels_.ground_truth);
}

void MessageFeed::onOdometry(const odometry_t& m) {
  if (!validFrame(channels_.odometry, m.frame)) return;
  if (!finite(m.pose)) {
    status_.error(channels_.odometry + ": non-finite pose at frame " + std::to_string(m.frame) + " (skipped)");
    return;
  }
  late(state_.addOdometry(m.frame, m.utime, fromMsg(m.pose), m.detections_used, m.num_points_removed, timing("odometry", m.timings)),
       channels_.odometry);
}

void MessageFeed::onAssociations(const associations_t& m) {
  if (!validFrame(channels_.associations, m.frame)) return;
  // Predictions are world positions under the tracker's ego pose; kept relative to the scan so
  // they sit where the tracker put them whatever ego estimate the image is drawn around.
  const Pose T_lidar_world = finite(m.ego_pose) ? fromMsg(m.ego_pose).inverse() : Pose::Identity();
  std::vector<AssociationMark> marks;
  for (const association_t& a : m.associations) {
    AssociationMark mark;
    mark.detection_index = a.detection_index;
    mark.track_id = a.track_id;
    mark.initialized = a.initialized;
    const Eigen::Vector3d p(a.predicted[0], a.predicted[1], a.predicted[2]);
    if (a.has_prediction && p.allFinite() && finite(m.ego_pose)) mark.predicted_lidar = T_lidar_world * p;
    marks.push_back(mark);
  }
  late(state_.addAssociations(m.frame, m.utime, std::move(marks), timing("tracker", m.timings)),
       channels_.associations);
}

void MessageFeed::onSlotState(const slot_state_t& m) {
  if (!validFrame(channels_.slot_state, m.frame)) return;
  if (!finite(m.ego_pose)) {
    status_.error(channels_.slot_state + ": non-finite ego pose at frame " + std::to_string(m.frame) + " (skipped)");
    return;
  }
  SlotStateData s;
  s.mode = m.mode;
  s.ego_pose = fromMsg(m.ego_pose);
  if (m.has_smoothed && finite(m.smoothed_pose)) {
    s.smoothed_frame = m.smoothed_frame;
    s.smoothed_pose = fromMsg(m.smoothed_pose);
  }
  for (const track_t& t : m.tracks) {
    TrackState ts;
    ts.id = t.id;
    ts.type = t.type;
    ts.size = Eigen::Vector3d(t.size[0], t.size[1], t.size[2]);
    ts.velocity = Eigen::Vector3d(t.velocity[0], t.velocity[1], t.velocity[2]);
    if (!finite(t.pose) || !ts.size.allFinite() || !ts.velocity.allFinite()) {
      status_.count("invalid_tracks");
      continue;
    }
    ts.pose = fromMsg(t.pose);
    ts.is_dynamic = t.is_dynamic;
    s.tracks.push_back(std::move(ts));
  }
  s.timing = timing("backend", m.timings);
  late(state_.addSlotState(m.frame, m.utime, std::move(s)), channels_.slot_state);
}

template <class Msg>
void MessageFeed::decodeAndFeed(const std::string& channel, const void* data, int size,
                                void (MessageFeed::*feed)(const Msg&)) {
  Msg m;
  Refusal why = decodeChecked(data, static_cast<size_t>(std::max(size, 0)), &m);
  if (!why) why = order_[channel].accept(m.frame);
  if (why)
    status_.refused(channel, why);
  else
    (this->*feed)(m);
}

void MessageFeed::handle(const std::string& channel, const void* data, int size) {
  if (channel == channels_.scan)
    decodeAndFeed(channel, data, size, &MessageFeed::onScan);
  else if (channel == channels_.detections)
    decodeAndFeed(channel, data, size, &MessageFeed::onDetections);
  else if (channel == channels_.ground_truth)
    decodeAndFeed(channel, data, size, &MessageFeed::onGroundTruth);
  else if (channel == channels_.odometry)
    decodeAndFeed(channel, data, size, &MessageFeed::onOdometry);
  else if (channel == channels_.associations)
    decodeAndFeed(channel, data, size, &MessageFeed::onAssociations);
  else if (channel == channels_.slot_state)
    decodeAndFeed(channel, data, size, &MessageFeed::onSlotState);
}

}  // namespace dlslot::renderer
