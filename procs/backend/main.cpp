// dlslot-backend: ODOMETRY + ASSOCIATIONS of a frame -> the sliding-window optimization ->
// SLOT_STATE. Live over LCM, or offline from a recorded log (--offline IN --out OUT).
#include <lcm/lcm-cpp.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <cstdio>
#include <iostream>
#include <map>
#include <stdexcept>

#include "backend/backend_messages.hpp"
#include "backend/sliding_window.hpp"
#include "dlslot/convert.hpp"
#include "dlslot/frame_joiner.hpp"
#include "dlslot/heap_memory.hpp"
#include "dlslot/kitti.hpp"
#include "dlslot/lcm_log.hpp"
#include "dlslot/node.hpp"
#include "dlslot/point_cloud_t.hpp"
#include "dlslot/timing_stats.hpp"

using namespace dlslot;
using namespace dlslot::backend;

namespace {

struct OdometryPart {
  int64_t utime = 0;
  OdometryInput odometry;
};
struct AssociationsPart {
  int64_t utime = 0;
  std::vector<ObservationInput> observations;
  std::shared_ptr<const PointCloud> scan;  // the frame's, when it arrived (per-object registration)
};
using Joiner = FrameJoiner<OdometryPart, AssociationsPart>;

BackendInput toInput(const Joiner::Joined& j) {
  BackendInput in;
  in.frame = j.frame;
  in.utime = j.a ? j.a->utime : j.b->utime;
  if (j.a) in.odometry = j.a->odometry;
  in.associations_missing = !j.b;
  if (j.b) {
    in.observations = j.b->observations;
    in.scan = j.b->scan;
  }
  return in;
}

// The true poses of --ego-truth, re-based on frame 0 as the odometry's world is.
std::vector<Pose> readTrueEgo(const std::string& path) {
  std::vector<Pose> truth = kitti::readPoses(path);
  if (truth.empty()) throw std::runtime_error(path + ": no poses");
  const Pose origin_inv = truth.front().inverse();
  for (Pose& T : truth) T = origin_inv * T;
  return truth;
}

// --ego-truth: the odometry of frame k replaced by the true motion, trusted to 1 mm and 0.01 mrad
// a frame. What the objects would get from a perfect ego: the bound no ego estimate can beat, for
// the object side alone.
void useTrueEgo(const std::vector<Pose>& truth, const std::string& path, BackendInput& in) {
  if (in.frame < 0 || in.frame >= static_cast<int>(truth.size()))
    throw std::runtime_error(path + ": no pose for frame " + std::to_string(in.frame) + " (file has " +
                             std::to_string(truth.size()) + ")");
  OdometryInput odometry;
  odometry.pose = truth[in.frame];
  odometry.delta = in.frame == 0 ? Pose::Identity() : truth[in.frame - 1].inverse() * truth[in.frame];
  Vector6 sigma;
  sigma << 1e-3, 1e-3, 1e-3, 1e-5, 1e-5, 1e-5;
  odometry.covariance = sigma.cwiseAbs2().asDiagonal();
  in.odometry = odometry;
}

double nowSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

void setCounter(ProcessStatus& status, const std::string& name, int64_t value) {
  status.count(name, value - status.counter(name));
}

void report(ProcessStatus& status, const BackendOutput& out) {
  status.frameDone(out.frame, out.stats.total_ms);
  setCounter(status, "last_solve_us", static_cast<int64_t>(1000.0 * out.stats.solve_ms));
  setCounter(status, "last_marginalize_us", static_cast<int64_t>(1000.0 * out.stats.marginalize_ms));
  setCounter(status, "last_iterations", out.stats.iterations);
  setCounter(status, "last_final_cost_milli", static_cast<int64_t>(1000.0 * out.stats.final_cost));
  setCounter(status, "last_prior_dim", out.stats.prior_dim);
  setCounter(status, "tracks", static_cast<int64_t>(out.tracks.size()));
  if (out.odometry_missing) status.count("odometry_missing");
  if (out.associations_missing) status.count("associations_missing");
  if (out.static_to_dynamic) status.count("static_to_dynamic", out.static_to_dynamic);
  for (int k = 0; k < kNumRegistrationOutcomes; ++k)
    if (out.registrations[k])
      status.count(std::string("registration_") + toString(static_cast<RegistrationOutcome>(k)), out.registrations[k]);
  if (out.registration_no_previous) status.count("registration_no_previous", out.registration_no_previous);
  if (out.line_of_sight_pairs) status.count("line_of_sight_pairs", out.line_of_sight_pairs);
  if (out.side_pairs) status.count("side_pairs", out.side_pairs);
  if (out.missed_vehicles_measured) status.count("missed_vehicles_measured", out.missed_vehicles_measured);
  // The odometry factor's test (odometry_consistency.hpp): frames tested, and those where the
  // landmarks and objects disagreed with it beyond both covariances (down-weighted or reported).
  const OdometryCheck& c = out.odometry_check;
  if (c.outcome != OdometryCheckOutcome::kUntested) status.count("odometry_tested");
  if (c.disagreed()) {
    status.count("odometry_disagreement_frames");
    if (c.outcome == OdometryCheckOutcome::kDownweighted) status.count("odometry_downweighted_frames");
    status.warn("frame " + std::to_string(out.frame) + ": " + c.text());
  }
}

// Offline: every ODOMETRY and ASSOCIATIONS event of a log, joined by frame, in frame order.
int runOffline(const BackendConfig& config, const Channels& channels, const std::string& in_path,
               const std::string& out_path, const std::string& ego_truth_path) {
  const std::vector<Pose> ego_truth = ego_truth_path.empty() ? std::vector<Pose>{} : readTrueEgo(ego_truth_path);
  lcm::LogFile in(in_path, "r");
  if (!in.good()) throw std::runtime_error(in_path + ": cannot open LCM log for reading");
  Joiner joiner(std::numeric_limits<double>::infinity());
  // Every event goes through the guard (message_guard.hpp) as it would live; refused ones are
  // skipped, counted by channel and reason, and their frames treated as missing.
  ProcessStatus guard("backend");
  std::map<std::string, FrameOrder> order;
  std::map<int64_t, int> accepted;  // event index -> frame, for the copy below
  int rejected = 0;
  int64_t index = 0;
  auto decode = [&](const lcm::LogEvent& ev, auto* msg) {
    Refusal why = decodeChecked(ev.data, static_cast<size_t>(std::max(ev.datalen, 0)), msg);
    if (!why) why = order[ev.channel].accept(msg->frame);
    if (why) guard.refused(ev.channel, why, in_path + ": event " + std::to_string(index) + ": ");
    else accepted[index] = msg->frame;
    return !why;
  };
  // The newest scans (per-object registration), by frame: a frame's scan comes before its
  // associations, but the player's next scans may too (the tracker answers later), so the newest
  // few are kept, as live.
  const bool use_scans = !config.registration_types.empty() && config.mode != Mode::kOdometryOnly;
  std::map<int, std::shared_ptr<const PointCloud>> scans;
  std::map<std::string, FrameOrder> scan_order;
  LogEnvelopes envelopes(in_path);  // every event verified as it would be live (lcm_log.hpp)
  SlidingWindow window(config);
  TimingStats total, solve, marginalize;
  int frames = 0, missing_odometry = 0, missing_associations = 0;
  int64_t landmarks = 0, moving = 0, switched = 0;  // summed over frames
  std::array<int64_t, kNumRegistrationOutcomes> registrations{};
  int64_t registration_no_previous = 0, registration_points = 0, line_of_sight_pairs = 0, side_pairs = 0, missed = 0;
  double registration_residual_sq = 0;
  int odometry_tested = 0, odometry_disagreed = 0, odometry_downweighted = 0;
  double odometry_max_disagreement_m = 0;
  std::vector<double> odometry_chi2;  // of the tested frames
  std::map<int, slot_state_t> states;
  std::map<int, int> inputs_left;  // frame -> its input events not yet copied to the output
  // Frames are solved as they are released, as live: when both their parts are read, or a later
  // frame's are (the other part is missing). So only the newest few scans are held. A part of a
  // frame already solved is late, as live, and left out of the frame's inputs.
  const auto late = [&](int frame) {
    guard.warn(in_path + ": event " + std::to_string(index) + ": frame " + std::to_string(frame) +
               " arrived after the frame was solved");
    accepted.erase(index);
  };
  const auto solveFrame = [&](const Joiner::Joined& j) {
    BackendInput input = toInput(j);
    if (!ego_truth.empty()) useTrueEgo(ego_truth, ego_truth_path, input);
    const BackendOutput result = window.process(input);
    ++frames;
    missing_odometry += result.odometry_missing;
    missing_associations += result.associations_missing;
    total.add(result.stats.total_ms);
    solve.add(result.stats.solve_ms);
    marginalize.add(result.stats.marginalize_ms);
    for (const TrackEstimate& e : result.tracks) (e.dynamic ? moving : landmarks) += 1;
    switched += result.static_to_dynamic;
    for (int k = 0; k < kNumRegistrationOutcomes; ++k) registrations[k] += result.registrations[k];
    registration_no_previous += result.registration_no_previous;
    registration_points += result.registration_points;
    registration_residual_sq += result.registration_residual_sq;
    line_of_sight_pairs += result.line_of_sight_pairs;
    side_pairs += result.side_pairs;
    missed += result.missed_vehicles_measured;
    const OdometryCheck& check = result.odometry_check;
    odometry_tested += check.outcome != OdometryCheckOutcome::kUntested;
    if (check.outcome != OdometryCheckOutcome::kUntested) odometry_chi2.push_back(check.chi2);
    if (check.disagreed()) {
      ++odometry_disagreed;
      odometry_downweighted += check.outcome == OdometryCheckOutcome::kDownweighted;
      odometry_max_disagreement_m = std::max(odometry_max_disagreement_m, check.disagreement_m);
      std::printf("  frame %d: %s\n", j.frame, check.text().c_str());
    }
    states[j.frame] = toMsg(result, toString(config.mode));
    inputs_left[j.frame] = (j.a ? 1 : 0) + (j.b ? 1 : 0);
  };
  for (; const lcm::LogEvent* raw = nextLogEvent(in, in_path); ++index) {
    const lcm::LogEvent* ev = envelopes.open(*raw, guard, in_path + ": event " + std::to_string(index) + ": ");
    if (!ev) continue;
    if (use_scans && ev->channel == channels.scan) {
      point_cloud_t m;
      Refusal why = decodeChecked(ev->data, static_cast<size_t>(std::max(ev->datalen, 0)), &m);
      if (!why) why = scan_order[ev->channel].accept(m.frame);
      if (why) guard.refused(ev->channel, why, in_path + ": event " + std::to_string(index) + ": ");
      else {
        scans[m.frame] = std::make_shared<const PointCloud>(dlslot::fromMsg(m));
        while (scans.size() > 3) scans.erase(scans.begin());
      }
    } else if (ev->channel == channels.odometry) {
      odometry_t m;
      if (decode(*ev, &m) && !joiner.addA(m.frame, OdometryPart{m.utime, fromMsg(m)}, 0.0)) late(m.frame);
    } else if (ev->channel == channels.associations) {
      associations_t m;
      if (decode(*ev, &m)) {
        AssociationsPart part{m.utime, observationsFromMsg(m, &rejected), nullptr};
        if (const auto it = scans.find(m.frame); it != scans.end()) part.scan = it->second;
        if (!joiner.addB(m.frame, std::move(part), 0.0)) late(m.frame);
      }
    }
    for (const Joiner::Joined& j : joiner.release(0.0)) solveFrame(j);
  }
  for (const Joiner::Joined& j : joiner.flush()) solveFrame(j);
  int64_t refused = 0;
  for (const auto& [what, n] : guard.refusals()) refused += n;
  if (!out_path.empty()) {
    // The output is the input run with this SLOT_STATE instead of the recorded one (if any):
    // every other event is copied in order, and a frame's SLOT_STATE follows its last input,
    // so dlslot-eval can evaluate it like a live run.
    lcm::LogFile out(out_path, "w");
    if (!out.good()) throw std::runtime_error(out_path + ": cannot open LCM log for writing");
    lcm::LogFile again(in_path, "r");
    int64_t n = 0;
    std::vector<uint8_t> buf;
    // Events that did not verify are left out; the rest are sealed again with the run's key (when
    // there is one), so the output verifies like the input.
    LogEnvelopes reopen(in_path);
    ProcessStatus refused_again("backend");
    MessageAuth sealer = reopen.auth().enabled() ? MessageAuth(*reopen.auth().key()) : MessageAuth();
    auto write = [&](const lcm::LogEvent& ev) {
      lcm::LogEvent copy = ev;
      const std::vector<uint8_t> sealed = sealer.sealCopy(ev.channel, ev.data, static_cast<size_t>(ev.datalen));
      copy.data = const_cast<uint8_t*>(sealed.data());
      copy.datalen = static_cast<int32_t>(sealed.size());
      copy.eventnum = n++;
      if (out.writeEvent(&copy) != 0) throw std::runtime_error(out_path + ": write failed");
    };
    for (int64_t i = 0; const lcm::LogEvent* raw = nextLogEvent(again, in_path); ++i) {
      const lcm::LogEvent* ev = reopen.open(*raw, refused_again, "");
      if (!ev || ev->channel == channels.slot_state) continue;
      write(*ev);
      const auto input = accepted.find(i);
      const int frame = input == accepted.end() ? -1 : input->second;
      auto left = inputs_left.find(frame);
      if (left == inputs_left.end() || --left->second > 0) continue;
      const slot_state_t& msg = states.at(frame);
      buf.resize(msg.getEncodedSize());
      msg.encode(buf.data(), 0, static_cast<int>(buf.size()));
      lcm::LogEvent state;
      state.timestamp = ev->timestamp;
      state.channel = channels.slot_state;
      state.datalen = static_cast<int32_t>(buf.size());
      state.data = buf.data();
      write(state);
    }
  }
  std::printf("backend (%s): %d frames, %d without odometry, %d without associations, %lld refused events, %d bad boxes\n",
              toString(config.mode).c_str(), frames, missing_odometry, missing_associations,
              static_cast<long long>(refused), rejected);
  for (const auto& [what, n] : guard.refusals()) std::printf("  refused %s: %lld\n", what.c_str(), static_cast<long long>(n));
  std::printf("  total %.2f ms mean, %.2f p95; solve %.2f mean; marginalize %.2f mean\n", total.mean(),
              total.percentile(95), solve.mean(), marginalize.mean());
  // What the objects give the ego: landmarks and moving objects in the graph per frame.
  std::printf("  objects in the graph per frame: %.1f static landmarks, %.1f moving; %lld landmarks turned dynamic\n",
              frames ? double(landmarks) / frames : 0.0, frames ? double(moving) / frames : 0.0,
              static_cast<long long>(switched));
  std::printf("  per-object registrations:");
  for (int k = 0; k < kNumRegistrationOutcomes; ++k)
    std::printf(" %s %lld", toString(static_cast<RegistrationOutcome>(k)), static_cast<long long>(registrations[k]));
  std::printf(", no previous scan %lld; line-of-sight pairs %lld, side pairs %lld; missed vehicles measured %lld\n",
              static_cast<long long>(registration_no_previous), static_cast<long long>(line_of_sight_pairs),
              static_cast<long long>(side_pairs), static_cast<long long>(missed));
  std::sort(odometry_chi2.begin(), odometry_chi2.end());
  const auto chi2At = [&](double q) {
    return odometry_chi2.empty() ? 0.0 : odometry_chi2[static_cast<size_t>(q * (odometry_chi2.size() - 1))];
  };
  std::printf("  odometry tested against the objects on %d frames (chi-square median %.2f, p99 %.2f, max %.2f): "
              "disagreed on %d (down-weighted %d), up to %.3f m\n",
              odometry_tested, chi2At(0.5), chi2At(0.99), chi2At(1.0), odometry_disagreed, odometry_downweighted,
              odometry_max_disagreement_m);
  int64_t attempts = 0;
  for (int k = 0; k < kNumRegistrationOutcomes; ++k) attempts += registrations[k];
  const int64_t ok = registrations[0] + registrations[1];
  if (attempts > 0)
    std::printf("  points per registered object %.0f; point-to-plane RMS of the measured ones %.4f m\n",
                double(registration_points) / attempts, ok ? std::sqrt(registration_residual_sq / ok) : 0.0);
  return 0;
}

int runLive(const BackendConfig& config, const Channels& channels, const NodeOptions& opts, double join_timeout_s) {
  Node node("backend", opts.lcm_url, channels);
  SlidingWindow window(config);
  Joiner joiner(join_timeout_s);
  const std::string mode = toString(config.mode);

  auto handleReady = [&] {
    for (const Joiner::Joined& j : joiner.release(nowSeconds())) {
      if (!j.a) node.status().timeout("ODOMETRY of frame " + std::to_string(j.frame));
      if (!j.b) node.status().timeout("ASSOCIATIONS of frame " + std::to_string(j.frame));
      try {
        const BackendOutput result = window.process(toInput(j));
        node.publish(channels.slot_state, toMsg(result, mode));
        report(node.status(), result);
      } catch (const std::exception& e) {
        node.status().error(std::string("frame ") + std::to_string(j.frame) + ": " + e.what());
      }
    }
  };
  node.subscribeFrames<odometry_t>(channels.odometry, [&](const odometry_t& m) {
    if (!joiner.addA(m.frame, OdometryPart{m.utime, fromMsg(m)}, nowSeconds()))
      node.status().warn("ODOMETRY of frame " + std::to_string(m.frame) + " arrived after the frame was solved");
    handleReady();
  });
  // The scans (per-object registration): the newest few, a frame's scan arrives before its
  // associations. Not subscribed when no class registers (nothing changes then).
  std::map<int, std::shared_ptr<const PointCloud>> scans;
  if (!config.registration_types.empty() && config.mode != Mode::kOdometryOnly)
    node.subscribeFrames<point_cloud_t>(channels.scan, [&](const point_cloud_t& m) {
      scans[m.frame] = std::make_shared<const PointCloud>(dlslot::fromMsg(m));
      while (scans.size() > 3) scans.erase(scans.begin());
    });
  node.subscribeFrames<associations_t>(channels.associations, [&](const associations_t& m) {
    int rejected = 0;
    AssociationsPart part{m.utime, observationsFromMsg(m, &rejected), nullptr};
    if (const auto s = scans.find(m.frame); s != scans.end()) part.scan = s->second;
    if (rejected) node.status().error(std::to_string(rejected) + " malformed boxes in ASSOCIATIONS of frame " + std::to_string(m.frame));
    if (!joiner.addB(m.frame, std::move(part), nowSeconds()))
      node.status().warn("ASSOCIATIONS of frame " + std::to_string(m.frame) + " arrived after the frame was solved");
    handleReady();
  });
  node.every(0.01, handleReady);  // releases frames whose other part timed out
  return node.run();
}

}  // namespace

int main(int argc, char** argv) {
  return runMain("dlslot-backend", [&] {
    NodeOptions opts;
    std::string mode, offline_in, offline_out, ego_truth;
    JoinTimeoutOption join_timeout;
    CommandLine cl("dlslot-backend",
                   "Sliding-window optimization of ego poses, landmarks and objects (DL-SLOT III-C): "
                   "ODOMETRY + ASSOCIATIONS -> SLOT_STATE.");
    opts.addTo(cl);
    cl.option("--mode", &mode, "slot | two-stage | odometry-only (overrides backend.mode)");
    cl.option("--offline", &offline_in, "read ODOMETRY and ASSOCIATIONS from this LCM log instead of the network");
    cl.option("--out", &offline_out,
              "with --offline: write the input log with this run's SLOT_STATE (replacing any recorded one) here");
    cl.option("--ego-truth", &ego_truth,
              "with --offline: replace the odometry by these true T_world_lidar poses (KITTI 3x4 lines, e.g. a "
              "simulated sequence's training/poses/0000.txt): the objects' accuracy with a perfect ego");
    join_timeout.addTo(cl, "a frame's other input (overrides backend.join_timeout_s)");
    if (!cl.parse(argc, argv)) return 0;
    if (!offline_out.empty() && offline_in.empty()) throw std::invalid_argument("--out needs --offline");
    if (!ego_truth.empty() && offline_in.empty()) throw std::invalid_argument("--ego-truth needs --offline");

    Channels channels;
    ConfigSection root = loadPipelineConfig(opts.config, channels);
    ConfigSection section = root.section("backend");
    BackendConfig config = BackendConfig::read(section);
    config.sweep = LidarConfig::read(root.section("lidar")).sweep;
    double join_timeout_s = 0;
    section.get("join_timeout_s", join_timeout_s);
    if (!(join_timeout_s > 0)) throw ConfigError(opts.config + ": backend.join_timeout_s: expected a time > 0 (s)");
    section.finish();
    join_timeout_s = join_timeout.resolve(join_timeout_s);
    if (!mode.empty()) config.mode = parseMode(mode);
    if (opts.check_config) return 0;
    retainFreedMemory();
    if (!offline_in.empty()) return runOffline(config, channels, offline_in, offline_out, ego_truth);
    return runLive(config, channels, opts, join_timeout_s);
  });
}
