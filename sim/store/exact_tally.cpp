#include "sim/store/exact_tally.h"

#include <fmt/core.h>

#include <cmath>
#include <cstdint>

#include "common/error.h"

namespace fiberlab::sim {

ExactTally::ExactTally(const TallyShape& s)
    : shape(s),
      count(s.bins(), 0),
      weight_sum(s.bin_cells(), 0),
      weight_sq_sum(s.bin_cells(), 0),
      exited(static_cast<std::size_t>(s.lobes) * s.channels, 0),
      absorbed(s.channels, 0),
      truncated(s.channels, 0),
      lost(s.channels, 0),
      roulette(s.channels, 0),
      lobe_weight_sq_sum(static_cast<std::size_t>(s.lobes) * s.channels, 0) {}

bool ExactTally::has_lobe_weight_sq_sum() const {
  for (Word w : lobe_weight_sq_sum)
    if (w != 0) return true;
  return false;
}

namespace {

void add_words(std::vector<ExactTally::Word>& a, const std::vector<ExactTally::Word>& b) {
  for (std::size_t i = 0; i < a.size(); ++i) a[i] += b[i];
}

std::uint64_t checked_add(std::uint64_t a, std::uint64_t b, const char* what) {
  std::uint64_t s;
  if (__builtin_add_overflow(a, b, &s))
    throw Error(fmt::format("sum of {} exceeds 2^64 - 1", what));
  return s;
}

}  // namespace

ExactTally& ExactTally::operator+=(const ExactTally& o) {
  if (!(shape == o.shape)) throw Error("internal error: adding tallies of different shapes");
  photons = checked_add(photons, o.photons, "photons");
  for (std::size_t i = 0; i < count.size(); ++i) count[i] = checked_add(count[i], o.count[i], "bin counts");
  add_words(weight_sum, o.weight_sum);
  add_words(weight_sq_sum, o.weight_sq_sum);
  add_words(exited, o.exited);
  add_words(absorbed, o.absorbed);
  add_words(truncated, o.truncated);
  add_words(lost, o.lost);
  add_words(roulette, o.roulette);  // two's complement: exact modulo 2^128
  add_words(lobe_weight_sq_sum, o.lobe_weight_sq_sum);
  return *this;
}

std::vector<ExactTally::Word> ExactTally::words() const {
  std::vector<Word> w;
  w.reserve(1 + count.size() + 2 * weight_sum.size() + 2 * exited.size() + 4 * absorbed.size());
  w.push_back(photons);
  w.insert(w.end(), count.begin(), count.end());
  for (const auto* v : {&weight_sum, &weight_sq_sum, &exited, &absorbed, &truncated, &lost, &roulette,
                        &lobe_weight_sq_sum})
    w.insert(w.end(), v->begin(), v->end());
  return w;
}

void ExactTally::from_words(const std::vector<Word>& w) {
  const std::size_t expected =
      1 + count.size() + 2 * weight_sum.size() + 2 * exited.size() + 4 * absorbed.size();
  if (w.size() != expected) throw Error("internal error: tally words of the wrong size");
  std::size_t i = 0;
  photons = static_cast<std::uint64_t>(w[i++]);
  for (auto& c : count) c = static_cast<std::uint64_t>(w[i++]);
  for (auto* v : {&weight_sum, &weight_sq_sum, &exited, &absorbed, &truncated, &lost, &roulette,
                  &lobe_weight_sq_sum})
    for (auto& x : *v) x = w[i++];
}

std::vector<ExactTally::Word> ExactTally::lobe_moments() const {
  const std::size_t L = shape.lobes, C = shape.channels;
  const std::size_t per_lobe = static_cast<std::size_t>(shape.n_theta) * shape.n_phi;
  std::vector<Word> m(2 * L * C, 0);
  if (has_lobe_weight_sq_sum()) {
    for (std::size_t i = 0; i < L * C; ++i) m[L * C + i] = lobe_weight_sq_sum[i];
  } else {
    for (std::size_t l = 0; l < L; ++l)
      for (std::size_t b = 0; b < per_lobe; ++b)
        for (std::size_t c = 0; c < C; ++c) m[L * C + l * C + c] += weight_sq_sum[(l * per_lobe + b) * C + c];
  }
  for (std::size_t i = 0; i < L * C; ++i) m[i] = exited[i];
  return m;
}

void ExactTally::lobe_counts(int l, std::vector<std::uint64_t>& out) const {
  const std::size_t bins = static_cast<std::size_t>(shape.n_theta) * shape.n_phi;
  const auto first = count.begin() + static_cast<std::ptrdiff_t>(l * bins);
  out.assign(first, first + static_cast<std::ptrdiff_t>(bins));
}

void ExactTally::lobe_sums(int l, BinSum which, std::vector<double>& value,
                           std::vector<std::int64_t>& residual) const {
  const std::size_t cells = static_cast<std::size_t>(shape.n_theta) * shape.n_phi * shape.channels;
  const Word* sums = (which == BinSum::S1 ? weight_sum : weight_sq_sum).data() + l * cells;
  value.resize(cells);
  residual.resize(cells);
  for (std::size_t i = 0; i < cells; ++i) split(sums[i], value[i], residual[i]);
}

std::vector<double> ExactTally::to_double(const std::vector<Word>& v) {
  std::vector<double> out;
  to_double(v, out);
  return out;
}


namespace {

// The float64 nearest E (ties to even), as an integer: E itself below 2^53.
// Below 2^64 (nearly every bin) the 64-bit conversion gives the same
// correctly rounded double as the 128-bit one, without its library call.
double nearest_double(ExactTally::Word e) {
  return e >> 64 == 0 ? static_cast<double>(static_cast<std::uint64_t>(e)) : static_cast<double>(e);
}

}  // namespace

std::vector<double> ExactTally::to_double_signed(const std::vector<Word>& v) {
  std::vector<double> out(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) out[i] = static_cast<double>(static_cast<__int128>(v[i])) / kScale;
  return out;
}

void ExactTally::to_double(const std::vector<Word>& v, std::vector<double>& out) {
  out.resize(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) out[i] = nearest_double(v[i]) / kScale;
}

void ExactTally::split(const std::vector<Word>& v, std::vector<double>& value,
                       std::vector<std::int64_t>& residual) {
  value.resize(v.size());
  residual.resize(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) split(v[i], value[i], residual[i]);
}

void ExactTally::split_large(Word e, double& value, std::int64_t& residual) {
  const double nearest = nearest_double(e);
  // Below 2^116 an ulp of E is at most 2^63, so |r| <= 2^62.
  if (e >> 116 != 0)
    throw Error(fmt::format("a bin sum of {:g} is too large for the result file's exact residual "
                            "(below 2^56, about 7.2e16)", nearest / kScale));
  const Word back = static_cast<Word>(nearest);  // exact: a whole number below 2^117
  value = nearest / kScale;
  residual = static_cast<std::int64_t>(e >= back ? static_cast<__int128>(e - back)
                                                 : -static_cast<__int128>(back - e));
}

std::ptrdiff_t ExactTally::join(const std::vector<double>& value,
                                const std::vector<std::int64_t>& residual, std::vector<Word>& out) {
  if (value.size() != residual.size()) throw Error("internal error: joining arrays of different sizes");
  out.resize(value.size());
  for (std::size_t i = 0; i < value.size(); ++i) {
    const double scaled = value[i] * kScale;  // exact (a power of two) for v below 2^68
    // Not a whole number >= 0 below 2^128 (NaN fails every comparison).
    if (!(scaled >= 0.0 && scaled < 0x1.0p128 && scaled == std::floor(scaled)))
      return static_cast<std::ptrdiff_t>(i);
    const Word base = static_cast<Word>(scaled);
    const std::int64_t r = residual[i];
    const Word magnitude = r >= 0 ? static_cast<Word>(r) : static_cast<Word>(-static_cast<__int128>(r));
    Word e;
    if (r >= 0 ? __builtin_add_overflow(base, magnitude, &e) : __builtin_sub_overflow(base, magnitude, &e))
      return static_cast<std::ptrdiff_t>(i);
    if (nearest_double(e) != scaled) return static_cast<std::ptrdiff_t>(i);  // does not round to v
    out[i] = e;
  }
  return -1;
}

std::vector<std::uint64_t> ExactTally::to_pairs(const std::vector<Word>& v) {
  std::vector<std::uint64_t> out;
  to_pairs(v, out);
  return out;
}

void ExactTally::to_pairs(const std::vector<Word>& v, std::vector<std::uint64_t>& out) {
  out.resize(2 * v.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    out[2 * i] = static_cast<std::uint64_t>(v[i] >> 64);
    out[2 * i + 1] = static_cast<std::uint64_t>(v[i]);
  }
}

std::vector<ExactTally::Word> ExactTally::from_pairs(const std::vector<std::uint64_t>& v) {
  std::vector<Word> out(v.size() / 2);
  for (std::size_t i = 0; i < out.size(); ++i)
    out[i] = (static_cast<Word>(v[2 * i]) << 64) | v[2 * i + 1];
  return out;
}

}  // namespace fiberlab::sim
