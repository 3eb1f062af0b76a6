#include "sim/store/zeroed_memory.h"

#include <sys/mman.h>

#include <cstdint>
#include <cstdlib>
#include <new>
#include <utility>

namespace fiberlab::sim {

namespace {
constexpr std::size_t kHugePage = std::size_t{2} << 20;
// Below this, calloc: a mapping of its own per small tally is not worth it.
constexpr std::size_t kMapAbove = std::size_t{1} << 20;
}  // namespace

ZeroedMemory::ZeroedMemory(std::size_t bytes) : bytes_(bytes) {
  if (bytes == 0) return;
  if (bytes < kMapAbove) {
    data_ = std::calloc(bytes, 1);
    if (!data_) throw std::bad_alloc();
    return;
  }
  // Whole huge pages (the kernel backs only aligned 2 MiB ranges with huge
  // pages: a partial last one would take 4 KiB faults, about 450 for a
  // 14.5 MB tally), and one more so that the start can be aligned.
  const std::size_t whole = (bytes + kHugePage - 1) / kHugePage * kHugePage;
  mapped_ = whole + kHugePage;
  mapping_ = mmap(nullptr, mapped_, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (mapping_ == MAP_FAILED) {
    mapping_ = nullptr;
    throw std::bad_alloc();
  }
  const auto start = reinterpret_cast<std::uintptr_t>(mapping_);
  data_ = reinterpret_cast<void*>((start + kHugePage - 1) & ~(kHugePage - 1));
  // Advice only: without transparent huge pages this fails and pages stay 4 KiB.
  madvise(data_, whole, MADV_HUGEPAGE);
}

ZeroedMemory::~ZeroedMemory() { release(); }

ZeroedMemory::ZeroedMemory(ZeroedMemory&& o) noexcept
    : data_(std::exchange(o.data_, nullptr)), mapping_(std::exchange(o.mapping_, nullptr)),
      bytes_(std::exchange(o.bytes_, 0)), mapped_(std::exchange(o.mapped_, 0)) {}

ZeroedMemory& ZeroedMemory::operator=(ZeroedMemory&& o) noexcept {
  if (this != &o) {
    release();
    data_ = std::exchange(o.data_, nullptr);
    mapping_ = std::exchange(o.mapping_, nullptr);
    bytes_ = std::exchange(o.bytes_, 0);
    mapped_ = std::exchange(o.mapped_, 0);
  }
  return *this;
}

void ZeroedMemory::release() {
  if (mapping_) munmap(mapping_, mapped_);
  else std::free(data_);
  data_ = mapping_ = nullptr;
  bytes_ = mapped_ = 0;
}

}  // namespace fiberlab::sim
