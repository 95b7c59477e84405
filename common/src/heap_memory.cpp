#include "dlslot/heap_memory.hpp"

#include <malloc.h>

namespace dlslot {

void retainFreedMemory() {
  mallopt(M_MMAP_THRESHOLD, 32 << 20);  // the largest glibc accepts on 64-bit
  mallopt(M_TRIM_THRESHOLD, 64 << 20);
}

}  // namespace dlslot
