// Simulated labels and detections: 2D boxes project where the camera sees the object, the
// detector finds well-seen objects, misses unseen ones, adds noise of the configured size, and
// scores its false positives (track id -1) below its true positives.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <vector>

#include "sim/calib.hpp"
#include "sim/detections.hpp"
#include "sim/labels.hpp"
#include "sim/simulation.hpp"

using namespace dlslot;

TEST(SimLabels, BoxesProjectIntoTheImageWhenTheCameraSeesThem) {
  const kitti::Calib calib = sim::kittiCalib();
  Box ahead;
  ahead.center = Eigen::Vector3d(15, 0, -0.9);
  ahead.size = Eigen::Vector3d(4.2, 1.7, 1.5);
  const auto ib = sim::projectToImage(ahead, calib);
  ASSERT_TRUE(ib);
  EXPECT_LT(ib->bbox[0], 609.6);  // straddles the principal point
  EXPECT_GT(ib->bbox[2], 609.6);
  // Its roof is just below the camera (8 cm below and 27 cm ahead of the lidar, pitched down by
  // 0.85 deg), its wheels 1.57 m below it: v = cy + f (dz + depth tan(pitch)) / depth at the near
  // face, 12.63 m ahead of the camera.
  EXPECT_GT(ib->bbox[1], 172.9);
  EXPECT_LT(ib->bbox[1], 200.0);
  EXPECT_NEAR(ib->bbox[3], 172.9 + 721.5 * (1.57 + 12.63 * 0.0148) / 12.63, 4.0);
  EXPECT_NEAR(ib->truncated, 0.0, 1e-9);
  Box behind = ahead;
  behind.center.x() = -15;
  EXPECT_FALSE(sim::projectToImage(behind, calib));
  Box aside = ahead;  // half out of the image on the left
  aside.center = Eigen::Vector3d(4, 4.5, -0.9);
  const auto cut = sim::projectToImage(aside, calib);
  ASSERT_TRUE(cut);
  EXPECT_EQ(cut->bbox[0], 0.0);
  EXPECT_GT(cut->truncated, 0.2);
  // A label row: rotation_y of a car heading along the lidar's x axis is -pi/2; alpha follows.
  const kitti::LabelRow row = sim::labelRow(3, 7, "Car", ahead, calib, 0);
  EXPECT_NEAR(row.box.rotation_y, -M_PI / 2, 1e-9);
  EXPECT_NEAR(row.alpha, row.box.rotation_y - std::atan2(row.box.bottom_center.x(), row.box.bottom_center.z()), 1e-9);
  EXPECT_EQ(row.frame, 3);
  EXPECT_EQ(row.track_id, 7);
}

TEST(SimDetections, FoundByPointsNoisyAsConfiguredFalsePositivesScoredLower) {
  sim::Scenario sc = sim::loadScenario(std::string(DLSLOT_SOURCE_DIR) + "/config/scenarios/intersection.yaml");
  sc.frames = 12;
  sim::Simulation sim(sc);
  int well_seen = 0, well_found = 0, unseen_found = 0, fp = 0, tp = 0;
  double tp_score = 0, fp_score = 0, err2 = 0;
  for (int k = 0; k < sc.frames; ++k) {
    const auto fd = sim.frame(k, 2);
    std::map<int, const kitti::LabelRow*> by_id;
    for (const auto& r : fd.detections) {
      ASSERT_TRUE(r.score);
      EXPECT_TRUE(std::isfinite(*r.score));  // a raw logit, as PointRCNN writes it
      EXPECT_EQ(r.occluded, -1);
      if (r.track_id < 0) {
        ++fp;
        fp_score += *r.score;
      } else {
        by_id[r.track_id] = &r;
      }
    }
    for (size_t i = 0; i < fd.labels.size(); ++i) {
      const kitti::LabelRow& l = fd.labels[i];
      if (l.type == "DontCare") continue;
      const Box truth = kitti::cameraToLidar(l.box, sim.calib());
      const auto it = by_id.find(l.track_id);
      // Points on this object: count the scan's points inside its box.
      int points = 0;
      for (Eigen::Index p = 0; p < fd.scan.points.cols(); ++p)
        points += fd.scan.object[p] >= 0 && truth.contains(fd.scan.points.col(p).head<3>().cast<double>(), 0.1);
      if (points >= 100) {
        ++well_seen;
        well_found += it != by_id.end();
      }
      if (it == by_id.end()) continue;
      ++tp;
      tp_score += *it->second->score;
      const Box det = kitti::cameraToLidar(it->second->box, sim.calib());
      const double range = truth.center.head<2>().norm();
      const double sigma = sc.detector.position_noise_m + sc.detector.position_noise_per_m * range;
      err2 += (det.center - truth.center).head<2>().squaredNorm() / (2 * sigma * sigma);
    }
    // Objects the lidar does not see (DontCare with no points) are rarely found.
    for (const auto& l : fd.labels)
      if (l.type == "DontCare" && l.occluded == 3) unseen_found += l.track_id >= 0 && by_id.count(l.track_id);
  }
  ASSERT_GT(well_seen, 50);
  EXPECT_GT(static_cast<double>(well_found) / well_seen, 0.85);
  EXPECT_EQ(unseen_found, 0);
  ASSERT_GT(tp, 50);
  ASSERT_GT(fp, 3);
  EXPECT_NEAR(std::sqrt(err2 / tp), 1.0, 0.3);  // position errors have the configured sigma
  EXPECT_GT(tp_score / tp, fp_score / fp + 2.0);  // logits: true positives several units higher
}

TEST(SimDetections, DriftProcessHasUnitVarianceAndItsCorrelationTime) {
  // Over many objects (keys): variance 1, each component correlated by exp(-dt / its time) at each
  // lag (3 s along, 1 s across), the two independent, and the same key gives the same value.
  const Eigen::Vector2d time_s(3.0, 1.0);
  for (const double dt : {0.1, 1.0, 3.0, 9.0}) {
    Eigen::Vector2d s00 = Eigen::Vector2d::Zero(), s11 = s00, s01 = s00;
    double cross = 0;
    const int n = 4000;
    for (int k = 0; k < n; ++k) {
      const Eigen::Vector2d a = sim::driftProcess(sim::streamKey({42, static_cast<uint64_t>(k)}), 5.0, time_s);
      const Eigen::Vector2d b = sim::driftProcess(sim::streamKey({42, static_cast<uint64_t>(k)}), 5.0 + dt, time_s);
      s00 += a.cwiseProduct(a);
      s11 += b.cwiseProduct(b);
      s01 += a.cwiseProduct(b);
      cross += a.x() * a.y();
    }
    for (int c = 0; c < 2; ++c) {
      EXPECT_NEAR(s00[c] / n, 1.0, 0.1) << dt << " " << c;
      EXPECT_NEAR(s11[c] / n, 1.0, 0.1) << dt << " " << c;
      EXPECT_NEAR(s01[c] / std::sqrt(s00[c] * s11[c]), std::exp(-dt / time_s[c]), 0.06) << dt << " " << c;
    }
    EXPECT_NEAR(cross / n, 0.0, 0.08) << dt;
  }
  EXPECT_EQ(sim::driftProcess(7, 1.5, time_s), sim::driftProcess(7, 1.5, time_s));
}

namespace {

// Each detected car's centre error along and across its heading (lidar frame), per frame.
std::map<int, std::vector<std::pair<int, Eigen::Vector2d>>> carErrors(const sim::Scenario& sc) {
  sim::Simulation sim(sc);
  std::map<int, std::vector<std::pair<int, Eigen::Vector2d>>> out;
  for (int k = 0; k < sc.frames; ++k) {
    const auto fd = sim.frame(k, 2);
    std::map<int, const kitti::LabelRow*> by_id;
    for (const auto& r : fd.detections)
      if (r.track_id >= 0) by_id[r.track_id] = &r;
    for (const auto& l : fd.labels) {
      const auto it = by_id.find(l.track_id);
      if (l.type != "Car" || it == by_id.end()) continue;
      const Box truth = kitti::cameraToLidar(l.box, sim.calib());
      const Box det = kitti::cameraToLidar(it->second->box, sim.calib());
      const Eigen::Vector2d e = (det.center - truth.center).head<2>();
      const Eigen::Vector2d along(std::cos(truth.yaw), std::sin(truth.yaw));
      out[l.track_id].push_back({k, Eigen::Vector2d(e.dot(along), along.x() * e.y() - along.y() * e.x())});
    }
  }
  return out;
}

// The along errors' correlation between consecutive frames of the same car, and the RMS along
// and across.
Eigen::Vector3d alongCorrelationAndRms(const std::map<int, std::vector<std::pair<int, Eigen::Vector2d>>>& errors) {
  double s01 = 0, s00 = 0, s11 = 0, along2 = 0, across2 = 0;
  int n = 0;
  for (const auto& [id, v] : errors)
    for (size_t i = 0; i < v.size(); ++i) {
      along2 += v[i].second.x() * v[i].second.x();
      across2 += v[i].second.y() * v[i].second.y();
      ++n;
      if (i == 0 || v[i - 1].first != v[i].first - 1) continue;
      s01 += v[i - 1].second.x() * v[i].second.x();
      s00 += v[i - 1].second.x() * v[i - 1].second.x();
      s11 += v[i].second.x() * v[i].second.x();
    }
  return Eigen::Vector3d(s01 / std::sqrt(s00 * s11), std::sqrt(along2 / n), std::sqrt(across2 / n));
}

}  // namespace

TEST(SimDetections, BoxesDriftAlongTheirHeadingWhenConfigured) {
  sim::Scenario sc = sim::loadScenario(std::string(DLSLOT_SOURCE_DIR) + "/config/scenarios/highway.yaml");
  sc.frames = 15;
  const Eigen::Vector3d white = alongCorrelationAndRms(carErrors(sc));
  EXPECT_LT(std::abs(white.x()), 0.3);  // the default: white noise, the same along and across
  EXPECT_NEAR(white.y() / white.z(), 1.0, 0.25);
  sc.detector.position_noise_m = 0.02;
  sc.detector.position_noise_per_m = 0.0;
  sc.detector.drift_m = 0.3;
  sc.detector.drift_across_ratio = 0.2;
  const Eigen::Vector3d drift = alongCorrelationAndRms(carErrors(sc));
  EXPECT_GT(drift.x(), 0.9);                     // exp(-0.1 / 3) with a little white noise
  EXPECT_NEAR(drift.y(), 0.3, 0.12);             // one drift process per car: few cars, loose
  EXPECT_LT(drift.z(), 0.5 * drift.y());         // across: 0.2 of it
}

TEST(SimDetections, WhiteNoiseAcrossTheHeadingByItsRatio) {
  // No drift, the white noise across the heading half of that along it; the default is the same
  // both ways (the test above).
  sim::Scenario sc = sim::loadScenario(std::string(DLSLOT_SOURCE_DIR) + "/config/scenarios/highway.yaml");
  sc.frames = 15;
  sc.detector.position_noise_across_ratio = 0.5;
  const Eigen::Vector3d e = alongCorrelationAndRms(carErrors(sc));
  EXPECT_LT(std::abs(e.x()), 0.3);  // still white
  EXPECT_NEAR(e.z() / e.y(), 0.5, 0.12);
}
