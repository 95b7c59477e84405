#include "backend/heap_memory.hpp"

#include <malloc.h>

namespace dlslot::backend {

void retainFreedMemory() {
  // The largest mmap threshold glibc accepts on 64-bit (32 MiB); a trim threshold far above
  // what the backend ever holds.
  mallopt(M_MMAP_THRESHOLD, 32 * 1024 * 1024);
  mallopt(M_TRIM_THRESHOLD, 1024 * 1024 * 1024);
}

}  // namespace dlslot::backend
