#include "run_log.hpp"

#include <lcm/lcm-cpp.hpp>

#include <algorithm>
#include <optional>
#include <type_traits>

#include "dlslot/associations_t.hpp"
#include "dlslot/convert.hpp"
#include "dlslot/detections_t.hpp"
#include "dlslot/frame_accounting.hpp"
#include "dlslot/ground_truth_t.hpp"
#include "dlslot/input_error.hpp"
#include "dlslot/lcm_log.hpp"
#include "dlslot/message_guard.hpp"
#include "dlslot/node.hpp"
#include "dlslot/odometry_t.hpp"
#include "dlslot/slot_state_t.hpp"

namespace dlslot::eval {
namespace {

double seconds(int64_t utime) { return utime * 1e-6; }

void addTimings(RunLog& run, const std::string& process, const std::vector<stage_timing_t>& timings) {
  for (const stage_timing_t& t : timings)
    run.timing_ms[t.name == "total" ? process : process + "." + t.name].add(t.ms);
}

// Tracks of the newest frame, moved into its lidar frame with the backend's own ego pose.
RunLog::Tracks tracksOf(const slot_state_t& msg, int track_max_unseen) {
  RunLog::Tracks out;
  out.stamp = seconds(msg.utime);
  out.ego = fromMsg(msg.ego_pose);
  const Pose lidar_world = out.ego.inverse();
  for (const track_t& t : msg.tracks) {
    if (msg.frame - t.last_seen_frame > track_max_unseen) continue;
    const Pose T_world_object = fromMsg(t.pose);
    Box world;
    world.center = T_world_object.translation();
    world.yaw = yawOf(T_world_object.linear());
    world.size = Eigen::Vector3d(t.size[0], t.size[1], t.size[2]);
    world.type = t.type;
    world.id = t.id;
    world.score = t.confidence;  // the lifecycle's confidence ranks tracks for sAMOTA
    Object o;
    o.box = world.transformed(lidar_world);
    o.velocity = (lidar_world.linear() * Eigen::Vector3d(t.velocity[0], t.velocity[1], t.velocity[2])).head<2>();
    const Eigen::Matrix3d C = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(t.velocity_covariance);
    if (!C.isZero()) o.velocity_covariance = (lidar_world.linear() * C * lidar_world.linear().transpose()).topLeftCorner<2, 2>();
    out.objects.push_back(o);
  }
  return out;
}

class LogReader {
 public:
  LogReader(const std::string& path, const Channels& channels, int track_max_unseen)
      : path_(path), ch_(channels), track_max_unseen_(track_max_unseen) {}

  RunLog read() {
    lcm::LogFile log(path_, "r");
    if (!log.good()) throw InputError(path_, 0, "cannot open the log for reading");
    for (const std::string* c : {&ch_.scan, &ch_.detections, &ch_.ground_truth, &ch_.odometry, &ch_.associations,
                                 &ch_.slot_state})
      run_.frame_counts[*c] = 0;
    // nextLogEvent (lcm_log.hpp) refuses truncated and corrupt logs, garbage between events and
    // headers that claim more than the file holds, before LCM allocates.
    // Each event's authentication envelope is checked as a live node would (lcm_log.hpp).
    LogEnvelopes envelopes(path_);
    int64_t count = 0;
    while (const lcm::LogEvent* raw = nextLogEvent(log, path_)) {
      const int64_t index = count++;
      if (const lcm::LogEvent* ev = envelopes.open(*raw, refusals_, path_ + ": event " + std::to_string(index) + ": "))
        handle(*ev, index);
    }
    if (count == 0) throw InputError(path_, 0, "the log holds no events");
    finishSlot();
    run_.refused = refusals_.refusals();
    return std::move(run_);
  }

 private:
  // Decodes through the guard (one place for every reader, message_guard.hpp); a refused event
  // is skipped, counted by channel and reason, and logged once per reason.
  template <class Msg>
  std::optional<Msg> decode(const lcm::LogEvent& ev, int64_t index) {
    Msg msg;
    Refusal why = decodeChecked(ev.data, static_cast<size_t>(std::max(ev.datalen, 0)), &msg);
    if constexpr (!std::is_same_v<Msg, process_status_t>)
      if (!why) why = order_[ev.channel].accept(msg.frame);
    if (why) {
      refusals_.refused(ev.channel, why, path_ + ": event " + std::to_string(index) + ": ");
      return std::nullopt;
    }
    return msg;
  }

  void handle(const lcm::LogEvent& ev, int64_t index) {
    const std::string& c = ev.channel;
    if (c == ch_.odometry) {
      const auto m = decode<odometry_t>(ev, index);
      if (!m) return;
      odometry_[m->frame] = {seconds(m->utime), fromMsg(m->pose)};
      addTimings(run_, "odometry", m->timings);
      run_.frames.insert(m->frame);
    } else if (c == ch_.slot_state) {
      const auto m = decode<slot_state_t>(ev, index);
      if (!m) return;
      slot_[m->frame] = {seconds(m->utime), fromMsg(m->ego_pose)};
      if (m->has_smoothed) smoothed_[m->smoothed_frame] = {seconds(m->smoothed_utime), fromMsg(m->smoothed_pose)};
      run_.tracks[m->frame] = tracksOf(*m, track_max_unseen_);
      OdometryChecks& checks = run_.odometry_checks ? *run_.odometry_checks : run_.odometry_checks.emplace();
      checks.tested += m->odometry_check != slot_state_t::ODOMETRY_UNTESTED;
      if (m->odometry_check == slot_state_t::ODOMETRY_DOWNWEIGHTED || m->odometry_check == slot_state_t::ODOMETRY_DISAGREED) {
        ++checks.disagreed;
        checks.downweighted += m->odometry_check == slot_state_t::ODOMETRY_DOWNWEIGHTED;
        checks.max_disagreement_m = std::max(checks.max_disagreement_m, m->odometry_disagreement_m);
        checks.disagreed_frames.push_back(m->frame);
      }
      addTimings(run_, "backend", m->timings);
      run_.frames.insert(m->frame);
    } else if (c == ch_.associations) {
      const auto m = decode<associations_t>(ev, index);
      if (!m) return;
      addTimings(run_, "tracker", m->timings);
      run_.frames.insert(m->frame);
    } else if (c == ch_.ground_truth) {
      const auto m = decode<ground_truth_t>(ev, index);
      if (!m) return;
      if (m->has_pose) truth_[m->frame] = {seconds(m->utime), fromMsg(m->pose)};
      RunLog::Labels& l = run_.labels[m->frame];
      l.stamp = seconds(m->utime);
      l.boxes = fromMsg(m->boxes);
      l.dontcare.clear();
      for (const box_t& b : m->dontcare)  // DontCare without a 3D extent cannot be matched in 3D
        if (b.size[0] > 0 && b.size[1] > 0 && b.size[2] > 0) l.dontcare.push_back(fromMsg(b));
      run_.frames.insert(m->frame);
    } else if (c == ch_.scan) {
      const auto m = decode<point_cloud_t>(ev, index);
      if (!m) return;
      run_.frames.insert(m->frame);
    } else if (c == ch_.detections) {
      const auto m = decode<detections_t>(ev, index);
      if (!m) return;
      addTimings(run_, "detector", m->timings);  // the player's files carry none
      run_.frames.insert(m->frame);
    } else if (c == ch_.status) {
      const auto m = decode<process_status_t>(ev, index);
      if (!m) return;
      run_.last_status[m->name] = *m;
      if (const int64_t kb = statusCounter(*m, "rss_kb"); kb > 0) run_.rss_kb[m->name].emplace_back(1e-6 * m->utime, kb);
      return;
    } else {
      return;
    }
    ++run_.frame_counts[c];
  }

  static Trajectory toTrajectory(const std::map<int, std::pair<double, Pose>>& poses) {
    Trajectory t;
    for (const auto& [frame, sp] : poses) t.add(frame, sp.first, sp.second);
    return t;
  }

  void finishSlot() {
    if (!odometry_.empty()) run_.sources["odometry"] = toTrajectory(odometry_);
    if (!slot_.empty()) run_.sources["slot"] = toTrajectory(slot_);
    // Final poses of the frames that left the window; the newest frames never left it, so they
    // keep their latest estimate.
    if (!smoothed_.empty()) {
      std::map<int, std::pair<double, Pose>> s = slot_;
      for (const auto& [frame, sp] : smoothed_) s[frame] = sp;
      run_.sources["slot_smoothed"] = toTrajectory(s);
    }
    run_.truth = toTrajectory(truth_);
  }

  std::string path_;
  Channels ch_;
  int track_max_unseen_;
  RunLog run_;
  std::map<int, std::pair<double, Pose>> odometry_, slot_, smoothed_, truth_;
  ProcessStatus refusals_{"eval"};
  std::map<std::string, FrameOrder> order_;
};

}  // namespace

RunLog readRunLog(const std::string& path, const Channels& channels, int track_max_unseen) {
  return LogReader(path, channels, track_max_unseen).read();
}

}  // namespace dlslot::eval
