// The backend allocates and frees the same few megabytes every frame (the marginalization's
// dense blocks and the new prior: 246 x 246 doubles each with 20 moving cars). glibc hands
// blocks this large back to the kernel when they are freed (mmap, heap trimming), so each
// frame paid again for their pages: about 120 page faults a frame, about 0.2 ms of the
// marginalization (measured on backend_bench's 20-car scene). The process keeps freed memory
// instead.
#pragma once

namespace dlslot::backend {

// Process-wide: large blocks come from the heap and a free heap top is not returned. Called
// by dlslot-backend at start and by the benchmark; harmless to call twice.
void retainFreedMemory();

}  // namespace dlslot::backend
