#include "backend/backend_messages.hpp"

#include "dlslot/convert.hpp"

namespace dlslot::backend {

OdometryInput fromMsg(const odometry_t& m) {
  OdometryInput o;
  o.pose = dlslot::fromMsg(m.pose);
  o.delta = dlslot::fromMsg(m.delta);
  o.covariance = covFromMsg(m.covariance);
  o.ok = m.status == odometry_t::STATUS_OK || m.status == odometry_t::STATUS_FIRST_FRAME;
  return o;
}

std::vector<ObservationInput> observationsFromMsg(const associations_t& m, int* rejected) {
  std::vector<ObservationInput> out;
  for (const association_t& a : m.associations) {
    if (!isValid(a.box_lidar)) {
      if (rejected) ++*rejected;
      continue;
    }
    ObservationInput o;
    o.track_id = a.track_id;
    o.initialized = a.initialized;
    o.box = dlslot::fromMsg(a.box_lidar);
    o.dynamic_guess = a.is_dynamic;
    o.confirmed = a.status != association_t::STATUS_TENTATIVE;
    o.confidence = a.confidence;
    out.push_back(o);
  }
  return out;
}

slot_state_t toMsg(const BackendOutput& out, const std::string& mode) {
  slot_state_t m;
  m.utime = out.utime;
  m.frame = out.frame;
  m.mode = mode;
  m.ego_pose = dlslot::toMsg(out.ego_pose);
  dlslot::toMsg(out.ego_covariance, m.ego_covariance);
  m.has_smoothed = out.smoothed.has_value();
  m.smoothed_frame = out.smoothed ? out.smoothed->frame : -1;
  m.smoothed_utime = out.smoothed ? out.smoothed->utime : 0;
  m.smoothed_pose = dlslot::toMsg(out.smoothed ? out.smoothed->pose : Pose::Identity());
  m.odometry_missing = out.odometry_missing;
  m.associations_missing = out.associations_missing;
  for (const TrackEstimate& e : out.tracks) {
    track_t t;
    t.id = e.id;
    t.type = e.type;
    t.pose = dlslot::toMsg(e.pose);
    for (int i = 0; i < 3; ++i) {
      t.size[i] = e.size[i];
      t.velocity[i] = e.velocity[i];
      t.angular_velocity[i] = e.angular_velocity[i];
      for (int j = 0; j < 3; ++j) t.velocity_covariance[3 * i + j] = e.velocity_covariance(i, j);
    }
    t.is_dynamic = e.dynamic;
    dlslot::toMsg(e.covariance, t.covariance);
    t.age = e.age;
    t.num_observations = e.num_observations;
    t.last_seen_frame = e.last_seen_frame;
    t.status = static_cast<int8_t>(e.status);
    t.confidence = e.confidence;
    m.tracks.push_back(t);
  }
  m.num_tracks = static_cast<int32_t>(m.tracks.size());
  m.iterations = out.stats.iterations;
  m.initial_cost = out.stats.initial_cost;
  m.final_cost = out.stats.final_cost;
  m.timings = dlslot::toMsg(StageTimings{{"solve", out.stats.solve_ms},
                                         {"covariance", out.stats.covariance_ms},
                                         {"marginalize", out.stats.marginalize_ms},
                                         {"total", out.stats.total_ms}});
  m.num_timings = static_cast<int32_t>(m.timings.size());
  const OdometryCheck& c = out.odometry_check;
  m.odometry_check = static_cast<int8_t>(c.outcome);
  m.odometry_chi2 = c.chi2;
  m.odometry_disagreement_m = c.disagreement_m;
  m.odometry_inflation = c.inflation;
  m.odometry_support = c.support;
  m.status_text = c.text();
  return m;
}

}  // namespace dlslot::backend
