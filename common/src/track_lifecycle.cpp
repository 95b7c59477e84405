#include "dlslot/track_lifecycle.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "dlslot/types.hpp"

namespace dlslot {
namespace {

// Weight of the newest frame in the exponential means: about the last 5 frames count.
constexpr double kRecentWeight = 0.2;

}  // namespace

const char* trackStatusName(TrackStatus status) {
  switch (status) {
    case TrackStatus::Tentative: return "tentative";
    case TrackStatus::Confirmed: return "confirmed";
    case TrackStatus::Coasting: return "coasting";
  }
  return "?";
}

ScoreScale scoreScaleFromName(const std::string& name) {
  if (name == "logit") return ScoreScale::Logit;
  if (name == "probability") return ScoreScale::Probability;
  throw std::invalid_argument("score_scale: expected 'logit' or 'probability', got '" + name + "'");
}

double detectionConfidence(double score, ScoreScale scale) {
  if (!std::isfinite(score)) return 0.0;
  if (scale == ScoreScale::Logit) return 1.0 / (1.0 + std::exp(-score));
  return std::clamp(score, 0.0, 1.0);
}

void ClassPolicy::validate() const {
  auto fail = [&](const std::string& what) { throw std::invalid_argument(name + "." + what); };
  if (types.empty()) fail("types: expected at least one KITTI type");
  // Boxes no detector class fits are only for the odometry's point removal: never objects.
  if (std::find(types.begin(), types.end(), kUnknownType) != types.end())
    fail(std::string("types: '") + kUnknownType + "' is the type of unclassified detections and is never tracked");
  if (std::isnan(min_score)) fail("min_score: expected a number");
  if (!(min_score_to_extend <= min_score))
    fail("min_score_to_extend: expected <= min_score, got " + std::to_string(min_score_to_extend));
  auto positive = [&](double v, const char* key) {
    if (!(v > 0) || !std::isfinite(v)) fail(std::string(key) + ": expected > 0, got " + std::to_string(v));
  };
  positive(gate_across_m, "gate_across_m");
  positive(gate_along_m, "gate_along_m");
  positive(young_gate_m, "young_gate_m");
  if (!(gate_growth_mps >= 0) || !std::isfinite(gate_growth_mps))
    fail("gate_growth_mps: expected >= 0, got " + std::to_string(gate_growth_mps));
  if (max_polynomial_degree < 1 || max_polynomial_degree > 3)
    fail("max_polynomial_degree: expected 1..3, got " + std::to_string(max_polynomial_degree));
  if (min_hits < 1) fail("min_hits: expected >= 1, got " + std::to_string(min_hits));
  if (!std::isfinite(moving_evidence)) fail("moving_evidence: expected a finite number");
  if (max_misses < 0) fail("max_misses: expected >= 0, got " + std::to_string(max_misses));
  if (output_coasting_frames < 0 || output_coasting_frames > max_misses)
    fail("output_coasting_frames: expected 0..max_misses, got " + std::to_string(output_coasting_frames));
}

const ClassPolicy* policyFor(const std::vector<ClassPolicy>& policies, const std::string& type) {
  for (const ClassPolicy& p : policies)
    if (std::find(p.types.begin(), p.types.end(), type) != p.types.end()) return &p;
  return nullptr;
}

TrackLifecycle::TrackLifecycle(double detection_confidence, const ClassPolicy& policy)
    : score_mean_(detection_confidence),
      evidence_(std::min(1.0, 1.0 / policy.min_hits)),
      confirmed_(policy.min_hits <= 1) {}

void TrackLifecycle::hit(double detection_confidence, int window_hits, const ClassPolicy& policy) {
  ++hits_;
  misses_ = 0;
  score_mean_ += kRecentWeight * (detection_confidence - score_mean_);
  hit_ratio_ += kRecentWeight * (1.0 - hit_ratio_);
  if (window_hits >= policy.min_hits) confirmed_ = true;
  evidence_ = confirmed_ ? 1.0 : std::max(evidence_, double(window_hits) / policy.min_hits);
}

void TrackLifecycle::miss() {
  ++misses_;
  hit_ratio_ -= kRecentWeight * hit_ratio_;
}

TrackStatus TrackLifecycle::status() const {
  if (!confirmed_) return TrackStatus::Tentative;
  return misses_ > 0 ? TrackStatus::Coasting : TrackStatus::Confirmed;
}

double TrackLifecycle::confidence() const { return std::clamp(score_mean_ * hit_ratio_ * evidence_, 0.0, 1.0); }

}  // namespace dlslot
