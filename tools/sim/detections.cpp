#include "detections.hpp"

#include <cmath>

#include "labels.hpp"
#include "object_shape.hpp"

namespace dlslot::sim {
namespace {

// Scores are raw logits, as PointRCNN publishes them (the tracker's score_scale: logit, and its
// per-class min_score thresholds, hold for both). Mean logit of a true positive: rises with the
// points on the object, from about -1 (a few points) to 9 (a well-seen object).
double scoreLogit(const std::string& type, int points) {
  const double scale = isVehicle(type) ? 80.0 : 30.0;
  return -1.0 + 10.0 * (1.0 - std::exp(-points / scale));
}

Box noisy(const DetectorTarget& target, const DetectorSpec& spec, Rng& rng) {
  const Box& truth = target.box;
  Box b = truth;
  const double range = truth.center.head<2>().norm();
  const double sigma = spec.position_noise_m + spec.position_noise_per_m * range;
  const Eigen::Vector2d along(std::cos(truth.yaw), std::sin(truth.yaw)), across(-along.y(), along.x());
  Eigen::Vector3d white(rng.normal(0, sigma), rng.normal(0, sigma), rng.normal(0, 0.5 * sigma));
  // The same in every direction, the draws serve as x and y (a scenario without the ratio keeps
  // its bytes); otherwise as along and across the heading.
  if (spec.position_noise_across_ratio != 1.0)
    white.head<2>() = white.x() * along + spec.position_noise_across_ratio * white.y() * across;
  b.center += white;
  const double drift = spec.drift_m + spec.drift_per_m * range;
  b.center.head<2>() += drift * (target.drift.x() * along + spec.drift_across_ratio * target.drift.y() * across);
  for (int i = 0; i < 3; ++i) b.size[i] *= std::max(0.5, 1.0 + rng.normal(0, spec.size_noise));
  const bool vehicle = isVehicle(truth.type);
  b.yaw += rng.normal(0, vehicle ? spec.yaw_noise : 0.3);  // pedestrians' headings are hard to see
  if (vehicle && rng.chance(spec.heading_flip)) b.yaw += M_PI;
  b.yaw = wrapAngle(b.yaw);
  if (truth.type == "Van" && rng.chance(0.3)) b.type = "Car";
  if (truth.type == "Pedestrian" && rng.chance(0.03)) b.type = "Cyclist";
  if (truth.type == "Cyclist" && rng.chance(0.03)) b.type = "Pedestrian";
  return b;
}

// A false positive of `type` standing on the ground at map point p (lidar frame result).
Box phantom(const std::string& type, const Eigen::Vector2d& p_map, const World& world, const Pose& T_map_lidar,
            Rng& rng) {
  Box b;
  b.type = type;
  b.size = sampleSize(type, rng);
  // Pushed away from the sensor by half its width: the returns were its near side.
  const Eigen::Vector2d away = (p_map - T_map_lidar.translation().head<2>()).normalized();
  const Eigen::Vector2d c = p_map + 0.5 * b.size.y() * away;
  b.center = Eigen::Vector3d(c.x(), c.y(), world.ground->height(c) + 0.5 * b.size.z());
  b.yaw = rng.uniform(-M_PI, M_PI);
  return b.transformed(T_map_lidar.inverse());
}

kitti::LabelRow detectionRow(int frame, int track_id, const Box& box, double score, const kitti::Calib& calib) {
  kitti::LabelRow row = labelRow(frame, track_id, box.type, box, calib, -1);
  row.truncated = -1;
  row.score = score;
  return row;
}

}  // namespace

Eigen::Vector2d driftProcess(uint64_t key, double t_s, const Eigen::Vector2d& time_s) {
  // E[cos(w dt)] over a Cauchy w of scale 1/time is exp(-|dt| / time); each cosine of a random
  // phase has variance 1/2, so sqrt(2 / kTerms) makes the sum's variance 1.
  constexpr int kTerms = 32;
  Eigen::Vector2d out = Eigen::Vector2d::Zero();
  for (int c = 0; c < 2; ++c) {
    Rng rng(streamKey({key, static_cast<uint64_t>(c)}));
    for (int k = 0; k < kTerms; ++k) {
      const double w = std::tan(M_PI * (rng.uniform() - 0.5)) / time_s[c];
      const double phase = rng.uniform(0.0, 2.0 * M_PI);
      out[c] += std::cos(w * t_s + phase);
    }
  }
  return std::sqrt(2.0 / kTerms) * out;
}

std::vector<bool> chooseGhosts(const World& world, const DetectorSpec& spec, uint64_t key) {
  Rng rng(key);
  std::vector<bool> ghosts(world.structures.size(), false);
  for (size_t i = 0; i < ghosts.size(); ++i) {
    const StructureKind k = world.structures[i].kind;
    const bool slim =
        k == StructureKind::Pole || k == StructureKind::Sign || k == StructureKind::Tree || k == StructureKind::Bush;
    ghosts[i] = slim && rng.chance(spec.ghost_fraction);
  }
  return ghosts;
}

std::vector<kitti::LabelRow> detect(int frame, const std::vector<DetectorTarget>& targets, const Scan& scan,
                                    const World& world, const std::vector<bool>& ghosts, const Pose& T_map_lidar,
                                    const DetectorSpec& spec, const kitti::Calib& calib, Rng& rng) {
  std::vector<kitti::LabelRow> rows;
  for (const DetectorTarget& t : targets) {
    const double p = spec.max_probability * (1.0 - std::exp(-M_LN2 * t.points / spec.points_for_half));
    if (!rng.chance(p)) continue;
    const Box b = noisy(t, spec, rng);
    rows.push_back(
        detectionRow(frame, t.track_id, b, rng.normal(scoreLogit(t.box.type, t.points), 1.5), calib));
  }
  // Points per structure this frame, and the static points near enough to fool the detector.
  std::vector<int> hits(world.structures.size(), 0);
  std::vector<size_t> clutter;
  for (size_t i = 0; i < scan.solid.size(); ++i) {
    if (scan.solid[i] < 0) continue;
    ++hits[world.grid->solids()[scan.solid[i]].owner];
    if (scan.points.col(i).head<2>().norm() < 50.0) clutter.push_back(i);
  }
  for (size_t s = 0; s < ghosts.size(); ++s) {
    if (!ghosts[s] || hits[s] < 5 || !rng.chance(0.5)) continue;
    const Eigen::Vector2d base = world.structures[s].base.head<2>();
    if ((base - T_map_lidar.translation().head<2>()).norm() > 40.0) continue;
    const Box b = phantom(rng.chance(0.8) ? "Pedestrian" : "Cyclist", base, world, T_map_lidar, rng);
    rows.push_back(detectionRow(frame, -1, b, rng.normal(0.0, 1.5), calib));
  }
  const int random_fp = clutter.empty() ? 0 : rng.poisson(spec.false_positives_per_frame);
  for (int k = 0; k < random_fp; ++k) {
    const size_t i = clutter[static_cast<size_t>(rng.uniform() * clutter.size())];
    const Eigen::Vector3d p_map = T_map_lidar * scan.points.col(i).head<3>().cast<double>();
    const double u = rng.uniform();
    const Box b = phantom(u < 0.6    ? "Car"
                          : u < 0.85 ? "Pedestrian"
                                     : "Cyclist",
                          p_map.head<2>(), world, T_map_lidar, rng);
    rows.push_back(detectionRow(frame, -1, b, rng.normal(-1.0, 1.5), calib));
  }
  return rows;
}

}  // namespace dlslot::sim
