#pragma once
// The batched tracer against the reference tracer, photon by photon, and
// the rows the two hand over on one photon's way (exits scored by expected
// value, Russian roulette), to rounding (tests/sim/test_batch_tracer.cpp,
// tests/sim/test_exit_normals.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "sim/life/batch_tracer.h"
#include "sim/life/source.h"
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


// The batched tracer against the reference tracer on 50,000 photons of `s`
// (its first incident direction), photon by photon: fate, path, exit,
// losses and the rows on the way to rounding (drift), all but a thousandth
// of them, and half of the light-guided ones; the same work counted. Prints
// how many are also equal to the last bit. `rows`, if given: the reference
// tracer's rows on the photons' way (exits scored by expected value).
inline void expect_same_photons_with(const Settings& s, const std::string& what_estimator,
                                     std::size_t* rows_out = nullptr) {
  const char* what = what_estimator.c_str();
  const std::uint64_t n = 50000;
  const Tracer reference(s);
  const BatchTracer batch(s);
  const auto inc = s.incidences().front();
  std::vector<PhotonOutcome> batched(n);
  std::vector<double> batched_phi(n);
  std::vector<int> seen(n, 0);
  // Exits scored by expected value on the way (rows before a photon's last).
  std::vector<std::vector<ScoredExitOutcome>> scored(n);
  TracerCounters counters;
  batch.trace(inc.theta_i, inc.phi_i, 0, n,
              [&](const FinishedPhotons& f) {
                for (int j = 0; j < f.n; ++j) {
                  const std::uint64_t i = f.photon[j];
                  // A photon that roulette ended ends on its row of that step.
                  if (!f.last[j] || (f.ended[j] && (f.weight[j] > 0.0 || f.roulette[j] != 0.0)))
                    scored[i].push_back({Vec3(f.dx[j], f.dy[j], f.dz[j]), f.segments[j], f.path[j],
                                         f.weight[j], f.medulla_path[j], f.scattered[j],
                                         f.roulette[j]});
                  if (!f.last[j]) continue;
                  batched[i] = f.outcome(j);
                  batched_phi[i] = f.phi_i[j];
                  ++seen[i];
                }
              },
              counters);
  int differ = 0, long_paths = 0, long_differ = 0, bit_equal = 0;
  constexpr int kLongPath = 50;
  double diverged_segments = 0.0;  // over photons whose paths came apart
  TracerCounters reference_counters;
  std::size_t rows = 0;
  for (std::uint64_t i = 0; i < n; ++i) {
    ASSERT_EQ(seen[i], 1) << "photon " << i << " reported " << seen[i] << " times";
    LaunchedPhoton p = launch_photon(s.seed, i, inc.theta_i, inc.phi_i, s.source.phi_i_uniform);
    const PhotonOutcome r = reference.trace(p.wi, p.h, p.rng, &reference_counters);
    ASSERT_EQ(batched_phi[i], p.phi_i);
    const PhotonOutcome& b = batched[i];
    rows += r.scored.size();
    bool same_losses = r.losses.size() == b.losses.size();
    for (std::size_t k = 0; same_losses && k < r.losses.size(); ++k)
      same_losses = std::abs(r.losses[k].weight - b.losses[k].weight) <= 1e-7 &&
                    std::abs(r.losses[k].path_length - b.losses[k].path_length) <=
                        1e-7 * (1.0 + r.losses[k].path_length);
    const bool same = r.fate == b.fate && r.segments == b.segments && same_losses &&
                      std::abs(r.path_length - b.path_length) <= 1e-7 * (1.0 + r.path_length) &&
                      (r.direction - b.direction).norm() <= drift(r.segments) &&
                      (r.fate != PhotonFate::Exited ||
                       (std::abs(r.theta - b.theta) <= drift(r.segments) &&
                        std::abs(r.phi - b.phi) <= drift(r.segments))) &&
                      std::abs(r.weight - b.weight) <= drift(r.segments) &&
                      r.scattered == b.scattered &&
                      std::abs(r.medulla_path - b.medulla_path) <= 1e-7 * (1.0 + r.medulla_path) &&
                      same_scored(r.scored, scored[i]);
    // Light-guided paths are chaotic: after ~50 segments the last-bit
    // drift grows beyond any fixed tolerance (judged apart, below).
    const bool long_path = r.segments > kLongPath;
    differ += !same && !long_path;
    long_paths += long_path;
    long_differ += !same && long_path;
    bool equal = r.fate == b.fate && r.segments == b.segments && r.path_length == b.path_length &&
                 r.weight == b.weight && r.direction == b.direction &&
                 r.losses.size() == b.losses.size();
    for (std::size_t k = 0; equal && k < r.losses.size(); ++k)
      equal = r.losses[k].weight == b.losses[k].weight &&
              r.losses[k].path_length == b.losses[k].path_length;
    bit_equal += equal;
    diverged_segments += std::abs(r.segments - b.segments);
  }
  std::printf("%s: %d of %llu photons differ, %d equal to the last bit; of %d paths longer than %d "
              "segments, %d differ\n",
              what, differ, static_cast<unsigned long long>(n), bit_equal, long_paths, kLongPath,
              long_differ);
  EXPECT_LE(differ, static_cast<int>(n / 1000)) << what;
  // Expected-value scoring follows many more photons along light-guided
  // paths (past their TT exit) than the analog estimator does.
  EXPECT_LE(long_differ, long_paths / 2) << what;
  // The same work, counted lane by lane in the batch. A photon whose path
  // came apart (a light-guided one, after ~100 segments of last-bit drift)
  // has its events and normals for a different number of segments: at most
  // a few events per segment (repeated events of the consistency rule) and
  // about 1.7 candidate normals per event, hence 4 per segment of difference.
  EXPECT_NEAR(counters.events, reference_counters.events,
              1e-3 * reference_counters.events + 4.0 * diverged_segments) << what;
  EXPECT_NEAR(counters.normal_draws, reference_counters.normal_draws,
              1e-3 * reference_counters.normal_draws + 4.0 * diverged_segments) << what;
  EXPECT_EQ(counters.sampler_caps, reference_counters.sampler_caps) << what;
  if (rows_out) *rows_out = rows;
}

}  // namespace fiberlab::sim::testing
