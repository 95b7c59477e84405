// A scenario run for longer than it is written for stays valid: the ego stops at the end of its
// path and still sees the ground, the roadside and the traffic; and a sequence the disk cannot hold
// is an error naming the file, never empty scans written without a word (the 1000-frame highway
// soak had 263 empty scans from frame 498 on, of a simulation that had made their points).
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>

#include "dlslot/input_error.hpp"
#include "dlslot/kitti.hpp"
#include "sim/sim.hpp"
#include "sim/simulation.hpp"
#include "sim_scenario.hpp"

namespace fs = std::filesystem;
using namespace dlslot;

namespace {

// The scan of one frame with every object in range, as Simulation::frame makes it (which only
// makes frames in order: 1000 of them would take minutes).
sim::Scan scanAt(const sim::Simulation& s, int f) {
  const std::vector<Pose>& ego = s.motion().ego;
  sim::ScanInput in;
  in.world = &s.world();
  in.T_map_lidar = ego[f];
  in.period_s = s.scenario().frame_period_s;
  in.ego = sim::sweepMotion(f > 0 ? &ego[f - 1] : nullptr, ego[f],
                            f + 1 < static_cast<int>(ego.size()) ? &ego[f + 1] : nullptr, in.period_s);
  in.key = 1234 + f;
  for (const sim::Agent& agent : s.motion().agents) {
    const Box b = sim::agentBox(agent, f, *s.world().ground);
    if ((b.center - ego[f].translation()).head<2>().norm() > s.scenario().sensor.max_range_m + 10.0) continue;
    sim::agentSolids(agent, static_cast<int>(in.object_boxes.size()), f, *s.world().ground, in.object_solids);
    in.object_boxes.push_back(b);
  }
  return sim::scan(s.scenario().sensor, in, 2);
}

// A file size limit for this process (writes beyond it fail with EFBIG, as on a full disk);
// restored on destruction.
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    getrlimit(RLIMIT_FSIZE, &saved_);
    old_handler_ = std::signal(SIGXFSZ, SIG_IGN);  // the write fails instead of killing the process
    rlimit r = saved_;
    r.rlim_cur = bytes;
    setrlimit(RLIMIT_FSIZE, &r);
  }
  ~FileSizeLimit() {
    setrlimit(RLIMIT_FSIZE, &saved_);
    std::signal(SIGXFSZ, old_handler_);
  }

 private:
  rlimit saved_{};
  void (*old_handler_)(int) = SIG_DFL;
};

}  // namespace

TEST(SimLongRun, EgoAtTheEndOfItsRoadStillSeesTheWorld) {
  // highway.yaml is written for 300 frames; at 1000 the ego reaches the end of its road.
  const sim::Simulation s(sim::test::shippedScenario("highway", 1000));
  const int end = s.motion().ego_path_end_frame;
  ASSERT_GT(end, 400);
  ASSERT_LT(end, 800);
  EXPECT_EQ(sim::test::shippedScenario("highway", 300).frames, 300);
  EXPECT_EQ(sim::Simulation(sim::test::shippedScenario("highway", 300)).motion().ego_path_end_frame, -1);  // as written: never
  // Standing: the last 100 frames move the lidar by centimetres at most (its body still rocks).
  EXPECT_LT((s.motion().ego[999].translation() - s.motion().ego[899].translation()).head<2>().norm(), 0.05);
  for (int f : {end, 999}) {
    const sim::Scan scan = scanAt(s, f);
    int ground = 0, roadside = 0, objects = 0;
    for (size_t i = 0; i < scan.solid.size(); ++i) {
      ground += scan.solid[i] == -1;
      roadside += scan.solid[i] >= 0;
      objects += scan.object[i] >= 0;
    }
    EXPECT_GT(scan.points.cols(), 60000) << "frame " << f;
    EXPECT_GT(ground, 20000) << "frame " << f;
    EXPECT_GT(roadside, 1000) << "frame " << f;
    EXPECT_GT(objects, 100) << "frame " << f << ": the traffic queued behind and beside the ego";
  }
}

TEST(SimLongRun, WritesTheDiskCannotHoldAreErrorsNamingTheFile) {
  const fs::path dir = fs::temp_directory_path() / ("dlslot_sim_long_run_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const sim::Scenario sc = sim::test::shippedScenario("highway", 2);
  std::string error;
  {
    const FileSizeLimit limit(256 * 1024);  // a scan is ~1.7 MB
    try {
      sim::writeSequence(sc, 2, 1, dir.string(), "0000", {2, false});
    } catch (const InputError& e) {
      error = e.what();
    }
  }
  fs::remove_all(dir);
  EXPECT_NE(error.find("velodyne/0000/000000.bin"), std::string::npos) << error;
  EXPECT_NE(error.find("writing failed"), std::string::npos) << error;

  // Every KITTI writer checks its writes (/dev/full: every write fails with ENOSPC).
  PointCloud cloud = PointCloud::Ones(4, 10);
  EXPECT_THROW(kitti::writeVelodyne("/dev/full", cloud), InputError);
  EXPECT_THROW(kitti::writePoses("/dev/full", std::vector<Pose>(3, Pose::Identity())), InputError);
  EXPECT_THROW(kitti::writeTrackingLabels("/dev/full", std::vector<kitti::LabelRow>(2)), InputError);
}
