// The detector on a short simulated sequence (the intersection scenario, labels all around): its
// recall per class against the simulator's labels, with the evaluation docs/detector.md reports
// (bird's-eye centre distance <= 2 m, within 40 m).
#include <gtest/gtest.h>

#include "detector/detection_eval.hpp"
#include "detector/geometric_detector.hpp"
#include "sim/simulation.hpp"

using namespace dlslot;
using namespace dlslot::detector;

TEST(DetectorSequence, RecallOnSimulatedIntersection) {
  sim::Scenario sc = sim::loadScenario(std::string(DLSLOT_SOURCE_DIR) + "/config/scenarios/intersection.yaml");
  sc.frames = 8;
  sim::Simulation simulation(sc);
  const DetectorConfig cfg;
  const std::vector<EvalClass> classes = defaultEvalClasses();
  std::vector<MatchCounts> counts(classes.size());
  for (int f = 0; f < sc.frames; ++f) {
    const sim::Simulation::FrameData data = simulation.frame(f);
    std::vector<Box> labels;
    for (const kitti::LabelRow& row : data.labels)
      if (row.type != "DontCare") {
        Box b = kitti::cameraToLidar(row.box, simulation.calib());
        b.type = row.type;
        labels.push_back(b);
      }
    const DetectionResult r = detectObjects(data.scan.points, cfg);
    for (size_t c = 0; c < classes.size(); ++c) counts[c].add(matchFrame(labels, r.boxes, classes[c], EvalOptions{}));
  }
  // Measured on these 8 frames: Car 1.00 of 24 (precision 0.57), Pedestrian 0.84 of 19 (the
  // docs/detector.md's 60-frame numbers are 0.995 and 0.80). The thresholds leave room for small tuning only.
  ASSERT_GE(counts[0].labels, 10);
  ASSERT_GE(counts[1].labels, 5);
  EXPECT_GE(counts[0].recall(), 0.9) << counts[0].matched << " of " << counts[0].labels << " cars";
  EXPECT_GE(counts[1].recall(), 0.6) << counts[1].matched << " of " << counts[1].labels << " pedestrians";
  EXPECT_GE(counts[0].precision(), 0.4);
  std::printf("Car recall %.3f (%d labels) precision %.3f; Pedestrian recall %.3f (%d labels) precision %.3f\n",
              counts[0].recall(), counts[0].labels, counts[0].precision(), counts[1].recall(), counts[1].labels,
              counts[1].precision());
}
