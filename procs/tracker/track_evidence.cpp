#include "track_evidence.hpp"

#include <cmath>

namespace dlslot::tracker {

namespace {
constexpr double kGrid = 1.0 / (1 << 20);
}

void TrackEvidence::add(int frame, double score, const Eigen::Vector3d& world, double time_s) {
  if (hits == 0 || frame < first_frame) {
    first_frame = frame;
    first_time_s = time_s;
    first_position = world.head<2>();
  }
  if (hits == 0 || frame > last_frame) {
    last_frame = frame;
    last_time_s = time_s;
    last_position = world.head<2>();
  }
  score_sum += std::isfinite(score) ? score : 0.0;
  ++hits;
}

double evidenceFloor(const ClassPolicy& policy) {
  return policy.min_score_to_extend > -1e6 ? policy.min_score_to_extend : 0.0;
}

double trackScore(const TrackEvidence& e, const ClassPolicy& policy, const MotionEvidence& motion) {
  const double floor = evidenceFloor(policy);
  const double prior = policy.min_hits;
  return (e.score_sum + floor * (e.missed() + prior)) / (e.hits + e.missed() + prior) +
         (motion.moved(e) ? policy.moving_evidence : 0.0);
}

double distinctGridScore(double v, std::set<double>& taken) {
  double q = std::round(v / kGrid) * kGrid;
  while (!taken.insert(q).second) q += kGrid;
  return q;
}

void writeTrackScores(std::vector<kitti::LabelRow>& rows, const std::map<int, TrackEvidence>& evidence,
                      const std::map<int, const ClassPolicy*>& policy_of, const MotionEvidence& motion) {
  std::map<int, double> score;
  std::set<double> taken;
  for (const auto& [id, e] : evidence) score[id] = distinctGridScore(trackScore(e, *policy_of.at(id), motion), taken);
  for (kitti::LabelRow& r : rows)
    if (const auto s = score.find(r.track_id); s != score.end()) r.score = s->second;
}

}  // namespace dlslot::tracker
