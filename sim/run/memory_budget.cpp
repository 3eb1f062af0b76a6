#include "sim/run/memory_budget.h"

#include <fmt/core.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <limits>
#include <string>

#include "common/error.h"

namespace fiberlab::sim {

namespace {

constexpr std::uint64_t kU64Max = std::numeric_limits<std::uint64_t>::max();

// Saturating arithmetic: a huge config gives 2^64 - 1, never a wrapped small number.
std::uint64_t mul(std::uint64_t a, std::uint64_t b) {
  std::uint64_t r = 0;
  return __builtin_mul_overflow(a, b, &r) ? kU64Max : r;
}
std::uint64_t add(std::uint64_t a, std::uint64_t b) {
  std::uint64_t r = 0;
  return __builtin_add_overflow(a, b, &r) ? kU64Max : r;
}

std::uint64_t cgroup_limit() {
  std::ifstream in("/sys/fs/cgroup/memory.max");
  std::string text;
  if (!(in >> text) || text == "max") return kU64Max;
  try {
    return std::stoull(text);
  } catch (const std::exception&) {
    return kU64Max;
  }
}

std::uint64_t resource_limit(int resource) {
  struct rlimit r {};
  if (getrlimit(resource, &r) != 0 || r.rlim_cur == RLIM_INFINITY) return kU64Max;
  return r.rlim_cur;
}

double gib(std::uint64_t bytes) { return static_cast<double>(bytes) / (1024.0 * 1024 * 1024); }

}  // namespace

MemoryFootprint run_footprint(const Settings& s, int threads) {
  constexpr std::uint64_t kFixed = 16;  // sizeof(Tally::Fixed), __int128
  const std::uint64_t C = s.fiber.sigma_a.size();
  const std::uint64_t L = static_cast<std::uint64_t>(s.tally.lobes);
  const std::uint64_t bins =
      mul(mul(L, static_cast<std::uint64_t>(s.tally.n_theta)), static_cast<std::uint64_t>(s.tally.n_phi));
  const std::uint64_t K = s.incidences().size();
  MemoryFootprint f{};
  // sim/store/tally.h: bins x (count, S1[C], S2[C]), exited L x C, absorbed, truncated and lost C.
  f.per_tally = mul(kFixed, add(mul(bins, 2 * C + 1), add(mul(L, C), 3 * C)));
  f.thread_tallies = mul(f.per_tally, static_cast<std::uint64_t>(std::max(threads, 1)));
  f.result_tallies = mul(f.per_tally, K);
  // sim/store/result_file.h: weight_sum and weight_sq_sum (C doubles per bin each),
  // count (one uint64 per bin), per incident configuration; plus one
  // configuration's column copied out of a Tally while the result is assembled.
  const std::uint64_t per_k = mul(8, add(mul(bins, 2 * C + 1), add(mul(L, C), 3 * C)));
  f.float_copies = add(mul(per_k, K), mul(8, mul(bins, C)));
  f.total = add(add(f.thread_tallies, f.result_tallies), f.float_copies);
  return f;
}

std::uint64_t memory_available() {
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  std::uint64_t limit = pages > 0 && page > 0 ? mul(static_cast<std::uint64_t>(pages),
                                                    static_cast<std::uint64_t>(page))
                                              : kU64Max;
  limit = std::min({limit, cgroup_limit(), resource_limit(RLIMIT_AS), resource_limit(RLIMIT_DATA)});
  return limit;
}

void check_memory_budget(const Settings& s, int threads) {
  const MemoryFootprint f = run_footprint(s, threads);
  const std::uint64_t limit = memory_available();
  if (f.total <= limit) return;
  throw Error(fmt::format(
      "the run needs {:.2f} GiB for its tallies ({:.3f} GiB per tally x ({} threads + {} incident "
      "configurations) + {:.2f} GiB of float64 copies for the file) but at most {:.2f} GiB is "
      "available (lower tally.n_theta/n_phi, tally.lobes, the channels, the incident angles or "
      "--threads)",
      gib(f.total), gib(f.per_tally), std::max(threads, 1), s.incidences().size(),
      gib(f.float_copies), gib(limit)));
}

}  // namespace fiberlab::sim
