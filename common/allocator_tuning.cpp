#include "common/allocator_tuning.h"

#include <malloc.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cstdint>
#include <cstdlib>

namespace fiberlab {

namespace {
constexpr std::size_t kHugePage = std::size_t{2} << 20;
constexpr std::size_t kHeapStep = std::size_t{64} << 20;
}  // namespace

void tune_allocator() {
  // Failure leaves glibc's defaults: slower, never wrong.
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
  // One heap for every thread, grown 64 MiB at a time, advised as
  // transparent huge pages (the header says why).
  mallopt(M_ARENA_MAX, 1);
  mallopt(M_TOP_PAD, static_cast<int>(kHeapStep));
  void* probe = std::malloc(kHugePage);  // more than the heap holds yet: it grows
  const auto at = reinterpret_cast<std::uintptr_t>(probe);
  const auto brk = reinterpret_cast<std::uintptr_t>(sbrk(0));
  // Only when the probe came from the heap's top (glibc falls back to a
  // mapping of its own when the heap cannot grow): [probe, break) is then
  // the heap's free top.
  if (probe && at < brk && brk - at <= kHeapStep + 2 * kHugePage) {
    const auto start = (at + kHugePage - 1) & ~(kHugePage - 1);
    const auto end = brk & ~(kHugePage - 1);
    if (end > start) madvise(reinterpret_cast<void*>(start), end - start, MADV_HUGEPAGE);
  }
  std::free(probe);
}

}  // namespace fiberlab
