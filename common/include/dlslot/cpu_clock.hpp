// CPU time of the calling thread, for per-stage timings that mean the same on an idle machine
// and on one shared with other jobs (wall time there counts the time other processes ran).
#pragma once

#include <time.h>

namespace dlslot {

// Milliseconds of CPU time this thread has used (an arbitrary origin: take differences).
inline double threadCpuMs() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}

}  // namespace dlslot
