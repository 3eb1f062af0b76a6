#pragma once
// Comparing the rows two tracers hand over on one photon's way (exits
// scored by expected value, Russian roulette), to rounding: the batched
// tracer against the reference (tests/sim/test_batch_tracer.cpp,
// tests/sim/test_exit_normals.cpp).
#include <cmath>
#include <vector>

#include "sim/life/tracer.h"

namespace fiberlab::sim::testing {

// What the last-bit drift of a path after `segments` segments may move a
// direction or a weight by (about 1e-8 per segment on light-guided paths;
// expected-value scoring follows many more of them to their end than the
// analog estimator, whose photons mostly leave at TT).
inline double drift(int segments) { return 1e-7 * (1.0 + segments); }

// A photon's rows on its way with a roulette-only row (weight 0) joined to
// the next row when that is at the same point: the batched tracer may draw
// a normal over two steps (kRoundsPerStep rounds each) and then hands over
// the roulette and the exit of one event as two rows, the reference tracer
// as one.
inline std::vector<ScoredExitOutcome> joined(const std::vector<ScoredExitOutcome>& rows) {
  std::vector<ScoredExitOutcome> out;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    ScoredExitOutcome e = rows[k];
    if (e.weight == 0.0 && k + 1 < rows.size() && rows[k + 1].segments == e.segments &&
        rows[k + 1].path_length == e.path_length) {
      const double r = e.roulette;
      e = rows[++k];
      e.roulette += r;
    }
    out.push_back(e);
  }
  return out;
}

// The rows two tracers handed over on one photon's way (exits scored by
// expected value, Russian roulette), to rounding.
inline bool same_scored(const std::vector<ScoredExitOutcome>& a_rows,
                 const std::vector<ScoredExitOutcome>& b_rows) {
  const std::vector<ScoredExitOutcome> a = joined(a_rows), b = joined(b_rows);
  if (a.size() != b.size()) return false;
  for (std::size_t k = 0; k < a.size(); ++k)
    if (a[k].segments != b[k].segments ||
        (a[k].direction - b[k].direction).norm() > drift(a[k].segments) ||
        std::abs(a[k].path_length - b[k].path_length) > 1e-7 * (1.0 + a[k].path_length) ||
        std::abs(a[k].weight - b[k].weight) > drift(a[k].segments) ||
        std::abs(a[k].roulette - b[k].roulette) > drift(a[k].segments) ||
        a[k].scattered != b[k].scattered ||
        std::abs(a[k].medulla_path - b[k].medulla_path) > 1e-7 * (1.0 + a[k].medulla_path))
      return false;
  return true;
}

}  // namespace fiberlab::sim::testing
