// A synthetic frame's inputs as the odometry and the tracker publish them (for the backend's
// node tests): ODOMETRY and ASSOCIATIONS messages, with one malformed box per message.
#pragma once

#include <cmath>

#include "backend/backend_types.hpp"
#include "dlslot/associations_t.hpp"
#include "dlslot/convert.hpp"
#include "dlslot/odometry_t.hpp"

namespace dlslot::backend::test {

inline odometry_t odometryMsg(const BackendInput& in) {
  odometry_t o{};
  o.utime = in.utime;
  o.frame = in.frame;
  o.status = in.frame == 0 ? odometry_t::STATUS_FIRST_FRAME : odometry_t::STATUS_OK;
  o.pose = toMsg(in.odometry->pose);
  o.delta = toMsg(in.odometry->delta);
  // Like the odometry's scan-to-map covariance: optimistic (2 mm, 0.1 mrad), which the
  // backend scales by odometry_covariance_scale.
  Matrix6d covariance = Matrix6d::Zero();
  covariance.diagonal() << 4e-6, 4e-6, 4e-6, 1e-8, 1e-8, 1e-8;
  toMsg(covariance, o.covariance);
  return o;
}

inline associations_t associationsMsg(const BackendInput& in) {
  associations_t a{};
  a.utime = in.utime;
  a.frame = in.frame;
  a.ego_pose = toMsg(in.odometry ? in.odometry->pose : Pose::Identity());
  a.ego_pose_source = "odometry";
  for (const ObservationInput& obs : in.observations) {
    association_t as{};
    as.detection_index = static_cast<int32_t>(a.associations.size());
    as.track_id = obs.track_id;
    as.initialized = obs.initialized;
    as.box_lidar = toMsg(obs.box);
    as.box_world = toMsg(obs.box);
    as.is_dynamic = obs.dynamic_guess;
    as.status = obs.confirmed ? association_t::STATUS_CONFIRMED : association_t::STATUS_TENTATIVE;
    as.confidence = obs.confidence;
    a.associations.push_back(as);
  }
  a.num_associations = static_cast<int32_t>(a.associations.size());
  return a;
}

// The same with a malformed box (NaN size) added: the guard refuses such a message whole
// (message_guard.hpp), counted, never fatal.
inline associations_t malformedAssociationsMsg(const BackendInput& in) {
  associations_t a = associationsMsg(in);
  association_t bad{};
  bad.track_id = 999;
  bad.box_lidar.size[0] = std::nan("");
  a.associations.push_back(bad);
  a.num_associations = static_cast<int32_t>(a.associations.size());
  return a;
}

}  // namespace dlslot::backend::test
