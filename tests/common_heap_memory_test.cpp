// retainFreedMemory: a frame's scan-sized blocks, freed and allocated again the next frame, cost
// no new page faults (the pages stay with the process instead of going back to the kernel and
// coming back zeroed).
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <cstring>
#include <memory>
#include <vector>

#include "dlslot/heap_memory.hpp"

namespace {

long minorFaults() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_minflt;
}

// One frame of a process that decodes a scan: the message as received (2 MB), its four decoded
// float arrays (0.5 MB each) and the points (2 MB), all written and then freed. Returns the minor
// page faults of `frames` such frames.
long faultsOfFrames(int frames) {
  const long before = minorFaults();
  for (int f = 0; f < frames; ++f) {
    std::vector<std::unique_ptr<char[]>> blocks;
    for (size_t bytes : {2u << 20, 1u << 19, 1u << 19, 1u << 19, 1u << 19, 2u << 20}) {
      blocks.emplace_back(new char[bytes]);
      std::memset(blocks.back().get(), 1, bytes);
      asm volatile("" : : "r"(blocks.back().get()) : "memory");  // the writes are kept
    }
  }
  return minorFaults() - before;
}

constexpr long kPagesPerFrame = (6u << 20) / 4096;

}  // namespace

TEST(HeapMemory, AFramesBlocksAreReusedWithoutPageFaults) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "AddressSanitizer's allocator replaces glibc's, whose settings this is about";
#endif
  // glibc's defaults first (this process has not called retainFreedMemory): past its first frames
  // it still hands the freed top of the heap back to the kernel, and each frame faults its blocks
  // in again. Checked so that the test below can fail.
  faultsOfFrames(3);
  const long by_default = faultsOfFrames(10);
  EXPECT_GT(by_default, 5 * kPagesPerFrame) << "glibc's defaults no longer return freed blocks: "
                                            << by_default << " page faults in 10 frames";
  dlslot::retainFreedMemory();
  faultsOfFrames(1);  // the heap grows to a frame's size once
  const long retained = faultsOfFrames(10);
  EXPECT_LT(retained, kPagesPerFrame / 10) << retained << " page faults in 10 frames (one frame's blocks are "
                                           << kPagesPerFrame << " pages)";
}
