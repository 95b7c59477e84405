// libFuzzer target: one file reader, built once per reader with DLSLOT_FUZZ_FILE_<NAME> set.
// A clear InputError or ConfigError is the expected answer to bad input, anything else (another
// exception, a crash, a sanitizer finding) is a defect.
// The text and scan readers get the bytes from memory (kitti_stream.hpp: the same parsing and
// validation the path readers run once they have opened the file). The config and the run log
// go through a scratch file: yaml-cpp's loading and LCM's log reader take a path, and their cost
// per input is the parsing, not the file.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <sstream>
#include <string>

#include "dlslot/config.hpp"
#include "dlslot/input_error.hpp"
#include "dlslot/kitti.hpp"
#include "dlslot/kitti_stream.hpp"
#if defined(DLSLOT_FUZZ_FILE_TUM)
#include "trajectory.hpp"
#endif
#ifdef DLSLOT_FUZZ_FILE_RUN_LOG
#include "run_log.hpp"
#endif

namespace {

// In memory (tmpfs) where there is one: a file on disk costs most of an execution.
[[maybe_unused]] const std::string& scratch() {
  static const std::string path =
      (access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp") + std::string("/dlslot-fuzz-") + std::to_string(getpid());
  return path;
}

[[maybe_unused]] bool toScratch(const uint8_t* data, size_t size) {
  std::FILE* f = std::fopen(scratch().c_str(), "wb");
  if (!f) return false;
  std::fwrite(data, 1, size, f);
  return std::fclose(f) == 0;
}

void read(const uint8_t* data, size_t size) {
  using namespace dlslot;
  [[maybe_unused]] const std::string name = "fuzz-input";
  [[maybe_unused]] std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
#if defined(DLSLOT_FUZZ_FILE_LABELS)
  kitti::readTrackingLabels(in, name);
#elif defined(DLSLOT_FUZZ_FILE_CSV_DETECTIONS)
  kitti::readCsvDetections(in, name);
#elif defined(DLSLOT_FUZZ_FILE_POSES)
  kitti::readPoses(in, name);
#elif defined(DLSLOT_FUZZ_FILE_OXTS)
  kitti::oxtsToLidarPoses(kitti::readOxts(in, name), Pose::Identity());
#elif defined(DLSLOT_FUZZ_FILE_CALIB)
  kitti::readCalib(in, name);
#elif defined(DLSLOT_FUZZ_FILE_TIMES)
  kitti::readTimes(in, name);
#elif defined(DLSLOT_FUZZ_FILE_VELODYNE)
  kitti::readVelodyne(reinterpret_cast<const char*>(data), size, name);
#elif defined(DLSLOT_FUZZ_FILE_TUM)
  eval::readTum(in, name);
#elif defined(DLSLOT_FUZZ_FILE_CONFIG)
  if (!toScratch(data, size)) return;
  Channels channels;
  loadPipelineConfig(scratch(), channels);
#elif defined(DLSLOT_FUZZ_FILE_RUN_LOG)
  if (!toScratch(data, size)) return;
  eval::readRunLog(scratch(), Channels());
#else
#error "set DLSLOT_FUZZ_FILE_<READER>"
#endif
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    read(data, size);
  } catch (const dlslot::InputError&) {
  } catch (const dlslot::ConfigError&) {
  }
  return 0;
}
