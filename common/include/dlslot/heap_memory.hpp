// Every process that handles scans allocates and frees the same megabytes every frame: a scan
// is ~2 MB as it arrives, as it is decoded and as points (and the backend's marginalization
// builds and frees dense blocks of 246 x 246 doubles with 20 moving cars). glibc hands blocks
// this large back to the kernel when they are freed (mmap, heap trimming), so each frame paid
// again for their pages, faulted in and zeroed: the backend about 120 page faults a frame (0.2 ms
// of its marginalization, backend_bench's 20-car scene), the Foxglove bridge most of its CPU, the
// live mapper 7 % of its `perf` samples (docs/performance.md). A process keeps freed memory
// instead.
#pragma once

namespace dlslot {

// Process-wide: blocks up to 32 MB come from the heap, and the heap keeps up to 64 MB (some thirty
// scans) free at its top. Called by each program at start; harmless to call twice.
void retainFreedMemory();

}  // namespace dlslot
