#include "mapper/mapper_messages.hpp"

#include "dlslot/convert.hpp"

namespace dlslot::mapper {

MapperInput inputFromMsg(const slot_state_t& m) {
  MapperInput in;
  in.frame = m.frame;
  in.utime = m.utime;
  in.pose = fromMsg(m.ego_pose);
  for (const track_t& t : m.tracks) {
    TrackSnapshot s;
    s.id = t.id;
    const Pose T = fromMsg(t.pose);
    s.box.center = T.translation();
    s.box.yaw = yawOf(T.linear());
    s.box.size = Eigen::Vector3d(t.size[0], t.size[1], t.size[2]);
    s.box.type = t.type;
    s.box.id = t.id;
    s.velocity = Eigen::Vector3d(t.velocity[0], t.velocity[1], t.velocity[2]);
    s.dynamic = t.is_dynamic;
    s.observed = t.last_seen_frame == m.frame;
    in.tracks.push_back(std::move(s));
  }
  return in;
}

loop_event_t toMsg(const LoopEvent& e) {
  loop_event_t m;
  m.query_frame = e.query_frame;
  m.match_frame = e.match_frame;
  m.relative = dlslot::toMsg(e.verdict.registration.T_match_query);
  m.descriptor_distance = e.descriptor_distance;
  m.inlier_ratio = e.verdict.registration.inlier_ratio;
  m.rmse_m = e.verdict.registration.rmse_m;
  m.accepted = e.verdict.accepted;
  m.reason = e.verdict.reason;
  return m;
}

map_state_t mapStateMsg(const Mapper& mapper, int frame, int64_t utime, const Pose& slot_pose,
                        const std::vector<LoopEvent>& new_events) {
  map_state_t m;
  m.utime = utime;
  m.frame = frame;
  const MapperSnapshot now = mapper.snapshot();
  m.map_from_world = dlslot::toMsg(now.map_from_world);
  m.map_pose = dlslot::toMsg(now.map_from_world * slot_pose);
  m.keyframes = static_cast<int32_t>(now.keyframes);
  m.map_points = static_cast<int32_t>(now.map_voxels);
  m.removed_points = static_cast<int32_t>(now.removed_voxels);
  m.loops_accepted = mapper.loops().accepted();
  m.loops_rejected = mapper.loops().rejected();
  for (const LoopEvent& e : new_events) m.loops.push_back(toMsg(e));
  m.num_loops = static_cast<int32_t>(m.loops.size());
  return m;
}

}  // namespace dlslot::mapper
