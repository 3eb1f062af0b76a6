#pragma once
// A large array of bytes that starts as zeros without being written: the
// memory comes straight from the operating system (anonymous mmap), whose
// pages are zero until first touched, so a tally of which a run touches a
// quarter costs a quarter. Large arrays are asked for as transparent huge
// pages (2 MiB): a 14.5 MB tally then takes 8 page faults instead of 3500
// (page faults are expensive on virtual machines), and the scattered cells
// of a tally need fewer TLB entries.
//
// Small arrays (tests, tiny tallies) come from calloc.
#include <cstddef>

namespace fiberlab::sim {

class ZeroedMemory {
 public:
  ZeroedMemory() = default;
  explicit ZeroedMemory(std::size_t bytes);  // throws std::bad_alloc
  ~ZeroedMemory();
  ZeroedMemory(ZeroedMemory&& o) noexcept;
  ZeroedMemory& operator=(ZeroedMemory&& o) noexcept;
  ZeroedMemory(const ZeroedMemory&) = delete;
  ZeroedMemory& operator=(const ZeroedMemory&) = delete;

  void* data() const { return data_; }
  std::size_t size() const { return bytes_; }

 private:
  void release();

  void* data_ = nullptr;     // aligned start handed out
  void* mapping_ = nullptr;  // what mmap returned (nullptr: calloc'ed)
  std::size_t bytes_ = 0, mapped_ = 0;
};

}  // namespace fiberlab::sim
