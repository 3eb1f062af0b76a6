#include "common/allocator_tuning.h"

#include <malloc.h>

namespace fiberlab {

void keep_freed_memory_for_reuse() {
  // Failure leaves glibc's defaults: slower, never wrong.
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
}

}  // namespace fiberlab
