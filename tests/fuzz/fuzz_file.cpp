// libFuzzer target: one file reader, built once per reader with DLSLOT_FUZZ_FILE_<NAME> set.
// The input is written to a scratch file and read back; a clear InputError or ConfigError is
// the expected answer to bad input, anything else (another exception, a crash, a sanitizer
// finding) is a defect.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <string>

#include "dlslot/config.hpp"
#include "dlslot/input_error.hpp"
#include "dlslot/kitti.hpp"
#if defined(DLSLOT_FUZZ_FILE_TUM) || defined(DLSLOT_FUZZ_FILE_POSES_EVAL)
#include "trajectory.hpp"
#endif
#ifdef DLSLOT_FUZZ_FILE_RUN_LOG
#include "run_log.hpp"
#endif

namespace {

// In memory (tmpfs) where there is one: a file on disk costs most of an execution.
const std::string& scratch() {
  static const std::string path =
      (access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp") + std::string("/dlslot-fuzz-") + std::to_string(getpid());
  return path;
}

void read(const std::string& path) {
  using namespace dlslot;
#if defined(DLSLOT_FUZZ_FILE_LABELS)
  kitti::readTrackingLabels(path);
#elif defined(DLSLOT_FUZZ_FILE_CSV_DETECTIONS)
  kitti::readCsvDetections(path);
#elif defined(DLSLOT_FUZZ_FILE_POSES)
  kitti::readPoses(path);
#elif defined(DLSLOT_FUZZ_FILE_OXTS)
  kitti::oxtsToLidarPoses(kitti::readOxts(path), Pose::Identity());
#elif defined(DLSLOT_FUZZ_FILE_CALIB)
  kitti::readCalib(path);
#elif defined(DLSLOT_FUZZ_FILE_TIMES)
  kitti::readTimes(path);
#elif defined(DLSLOT_FUZZ_FILE_VELODYNE)
  kitti::readVelodyne(path);
#elif defined(DLSLOT_FUZZ_FILE_CONFIG)
  Channels channels;
  loadPipelineConfig(path, channels);
#elif defined(DLSLOT_FUZZ_FILE_TUM)
  eval::readTrajectory(path, eval::TrajectoryFormat::Tum);
#elif defined(DLSLOT_FUZZ_FILE_RUN_LOG)
  eval::readRunLog(path, Channels());
#else
#error "set DLSLOT_FUZZ_FILE_<READER>"
#endif
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::FILE* f = std::fopen(scratch().c_str(), "wb");
  if (!f) return 0;
  std::fwrite(data, 1, size, f);
  std::fclose(f);
  try {
    read(scratch());
  } catch (const dlslot::InputError&) {
  } catch (const dlslot::ConfigError&) {
  }
  return 0;
}
