#pragma once
// A deflate compressor writing the zlib stream format (RFC 1950), which
// HDF5's deflate filter reads like its own output: libdeflate (measured
// faster than zlib's compressor, docs/PERFORMANCE.md), with its buffers kept
// across calls, since fresh memory costs a page fault per 4 KiB on these
// machines. Not thread-safe: one Deflater per thread.
#include <cstddef>
#include <vector>

struct libdeflate_compressor;

namespace fiberlab {

class Deflater {
 public:
  explicit Deflater(int level);  // throws std::bad_alloc
  ~Deflater();
  Deflater(Deflater&& o) noexcept;
  Deflater& operator=(Deflater&& o) noexcept;
  Deflater(const Deflater&) = delete;
  Deflater& operator=(const Deflater&) = delete;

  int level() const { return level_; }
  // The stream of bytes [data, data + bytes) followed by zeros up to
  // `padded` bytes (padded >= bytes), into `out` (resized to fit). Throws
  // fiberlab::Error if libdeflate fails (it cannot for a large enough buffer).
  void deflate(const unsigned char* data, std::size_t bytes, std::size_t padded,
               std::vector<unsigned char>& out);

 private:
  libdeflate_compressor* z_ = nullptr;
  int level_ = 0;
  std::vector<unsigned char> plain_;       // a padded input
  std::vector<unsigned char> compressed_;  // the output, at the bound's size
};

// This thread's Deflater at `level`, made on first use and kept (remade
// when another level is asked for): a compressor's tables are a few hundred
// KB of fresh memory, so every writer on a thread shares one.
Deflater& thread_deflater(int level);

}  // namespace fiberlab
