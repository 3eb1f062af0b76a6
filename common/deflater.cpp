#include "common/deflater.h"

#include <libdeflate.h>

#include <algorithm>
#include <cstring>
#include <new>
#include <optional>
#include <utility>

#include "common/error.h"

namespace fiberlab {

Deflater::Deflater(int level) : z_(libdeflate_alloc_compressor(level)), level_(level) {
  if (!z_) throw std::bad_alloc();
}

Deflater::~Deflater() {
  if (z_) libdeflate_free_compressor(z_);
}

Deflater::Deflater(Deflater&& o) noexcept
    : z_(std::exchange(o.z_, nullptr)), level_(o.level_), plain_(std::move(o.plain_)),
      compressed_(std::move(o.compressed_)) {}

Deflater& Deflater::operator=(Deflater&& o) noexcept {
  if (this != &o) {
    if (z_) libdeflate_free_compressor(z_);
    z_ = std::exchange(o.z_, nullptr);
    level_ = o.level_;
    plain_ = std::move(o.plain_);
    compressed_ = std::move(o.compressed_);
  }
  return *this;
}

void Deflater::deflate(const unsigned char* data, std::size_t bytes, std::size_t padded,
                       std::vector<unsigned char>& out) {
  const unsigned char* in = data;
  if (padded > bytes) {  // only an edge chunk: the rest is compressed in place
    if (plain_.size() < padded) plain_.resize(padded);
    std::memcpy(plain_.data(), data, bytes);
    std::fill(plain_.begin() + static_cast<std::ptrdiff_t>(bytes),
              plain_.begin() + static_cast<std::ptrdiff_t>(padded), 0);
    in = plain_.data();
  }
  // Into a buffer of the bound's size kept across calls (growing `out` to
  // the bound for every chunk would zero-fill what it does not use), then
  // the stream's bytes into `out`, whose capacity a caller can reuse.
  const std::size_t bound = libdeflate_zlib_compress_bound(z_, padded);
  if (compressed_.size() < bound) compressed_.resize(bound);
  const std::size_t size =
      libdeflate_zlib_compress(z_, in, padded, compressed_.data(), compressed_.size());
  if (size == 0) throw Error("internal error: libdeflate could not compress a chunk");
  out.assign(compressed_.begin(), compressed_.begin() + static_cast<std::ptrdiff_t>(size));
}

Deflater& thread_deflater(int level) {
  thread_local std::optional<Deflater> z;
  if (!z || z->level() != level) z.emplace(level);
  return *z;
}

}  // namespace fiberlab
