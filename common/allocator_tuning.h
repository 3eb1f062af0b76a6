#pragma once
// The process's allocator, tuned for fiberlab's pattern: large buffers (a
// tally's export, HDF5's chunk buffers, zlib's deflate state per chunk)
// allocated and freed many times in a row.
//
// By default glibc serves blocks above its mmap threshold (128 KiB at first)
// with fresh mappings and returns freed memory at the top of the heap to the
// kernel, so each of those allocations starts on untouched pages: a page
// fault per 4 KiB, which on these virtual machines costs more than the work
// done in the memory (measured: the fixed part of `fiberlab run` on a
// 90 x 180 x 8-lobe, 3-channel tally went from about 0.3 s to 0.12 s;
// docs/PERFORMANCE.md). Here blocks up to 32 MiB (glibc's largest threshold) come
// from the heap, and up to 256 MiB of freed heap is kept for reuse.
//
// Even first use is dear: a 4 KiB page fault costs about 12 us here (against
// about 3 us per 4 KiB for a 2 MiB transparent huge page, measured), and a
// 4 M-photon run took about 5,000 of them, a 1,000-photon run 3,700. So all
// threads share the one heap (glibc would give threads arenas of their own,
// mapped apart), which grows 64 MiB at a time and is advised as transparent
// huge pages (where the kernel allows them: "madvise" or "always"): about
// 1,700 faults per run with the tallies' own huge pages (sim/store/zeroed_memory.h).
// Peak memory grows by what the last huge pages hold beyond what is used (a
// few MiB).
namespace fiberlab {

// Call once, at the start of main (a program's choice, not a library's).
void tune_allocator();

}  // namespace fiberlab
