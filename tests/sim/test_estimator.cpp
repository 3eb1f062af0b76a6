// Expected-value scoring of exits (Settings::estimator, SPEC sections 5 and
// 6; docs/PHYSICS.md "Estimator"):
// - every photon's scored exits, its end and its masking losses, minus the
//   weight Russian roulette created for it (plus what it destroyed), add up
//   to its starting weight, to rounding, with scalar and Stokes light and
//   with Smith G1 masking;
// - the roulette term has expectation 0: its mean over many photons is
//   within 4 of its standard errors of 0 (mutation: survival with
//   probability w / (2 kRouletteWeight) instead of w / kRouletteWeight gives
//   a mean 37 standard errors below 0), and
//   the file's ledger exited + absorbed + truncated + lost - roulette =
//   launched holds to rounding;
// - the reported standard errors agree with the spread of the estimates over
//   many seeds, lobe by lobe, the last lobe (which collects several exits of
//   one photon in one bin) included. Mutations caught: S2 as the sum of the
//   squares of a photon's parts (ExitScorer::score_scored_exit calling
//   score_exit for a repeated bin) fails ErrorsMatchSpreadOverSeeds on the
//   last lobe; the photon going on at its full weight instead of weight x
//   (1 - P) (score_leaving_branch) fails LedgerClosesPerPhoton; the scorer
//   taking every row as its photon's first in its lobe
//   (ExitScorer::score_scored_exit, new_lobe always true) gives 2.48 (bins)
//   and 2.58 (lobe energy) on the last lobe of 2 and fails both spread tests;
// - Russian roulette ends a photon where it plays, right after an event.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "common/error.h"
#include "sim/life/source.h"
#include "sim/life/tracer.h"
#include "tests/sim/sim_test_support.h"
#include "tests/sim/spread_over_seeds.h"

namespace fiberlab::sim {
namespace {

using testing::expect_errors_match_spread;
using testing::expect_lobe_errors_match_spread;

// Each photon's scored exits + its final weight (exited or truncated) + its
// losses - what roulette created or destroyed = 1 (white fiber: nothing
// absorbed), to rounding.
void expect_ledger_closes(const Settings& s, const char* what) {
  const Tracer tracer(s);
  const auto inc = s.incidences().front();
  double worst = 0.0;
  std::size_t scored = 0;
  for (std::uint64_t i = 0; i < 20000; ++i) {
    LaunchedPhoton p = launch_photon(s.seed, i, inc.theta_i, inc.phi_i, false);
    const PhotonOutcome o = tracer.trace(p.wi, p.h, p.rng);
    double total = o.fate == PhotonFate::Lost ? 0.0 : o.weight;
    for (const ScoredExitOutcome& e : o.scored) total += e.weight - e.roulette;
    for (const WeightLoss& l : o.losses) total += l.weight;
    scored += o.scored.size();
    worst = std::max(worst, std::abs(total - 1.0));
  }
  std::printf("%s: %zu scored exits, worst |sum - 1| = %.3g\n", what, scored, worst);
  EXPECT_GT(scored, 20000u) << what;  // every photon scores R at its first event
  EXPECT_LE(worst, 1e-12) << what;
}

TEST(Estimator, LedgerClosesPerPhoton) {
  Settings s = testing::smooth_circle(30.0, 1);
  s.estimator = Estimator::ExpectedValue;
  testing::make_rough(s, 10.0, 3.0);
  s.fiber.eccentricity = 0.8;
  expect_ledger_closes(s, "gaussian 10, tilt 3, e 0.8");
  s.polarization = Polarization::Stokes;
  expect_ledger_closes(s, "stokes");
  s.polarization = Polarization::Scalar;
  s.fiber.roughness = testing::microfacet(MicrofacetModel::GGX, 0.3, 0.3, Masking::SmithG1);
  expect_ledger_closes(s, "ggx 0.3 smith_g1");
}

// Russian roulette plays right after an interface event, before the next
// segment (sim/life/photon_life.h step): a photon it ends travels no
// further, so it ends at the point of its last event, on the row with its
// roulette term. On a smooth fiber every point has one event, so an ended
// photon made one event more than it has segments. Mutation caught:
// roulette before the event (as a step's first action) ends each such
// photon one segment past its last event (events = segments).
TEST(Estimator, RouletteEndsPhotonWhereItPlays) {
  Settings s = testing::smooth_circle(17.0, 1);
  s.estimator = Estimator::ExpectedValue;
  s.fiber.eccentricity = 0.8;
  s.fiber.sigma_a = {0.2, 0.4, 0.8};
  const Tracer tracer(s);
  const auto inc = s.incidences().front();
  int ended = 0;
  for (std::uint64_t i = 0; i < 20000; ++i) {
    LaunchedPhoton p = launch_photon(s.seed, i, inc.theta_i, inc.phi_i, false);
    TracerCounters counters;
    const PhotonOutcome o = tracer.trace(p.wi, p.h, p.rng, &counters);
    if (o.fate != PhotonFate::Ended) continue;
    ++ended;
    ASSERT_FALSE(o.scored.empty()) << "photon " << i;
    const ScoredExitOutcome& last = o.scored.back();
    ASSERT_LT(last.roulette, 0.0) << "photon " << i;
    EXPECT_EQ(o.segments, last.segments) << "photon " << i;
    EXPECT_EQ(o.path_length, last.path_length) << "photon " << i;
    ASSERT_EQ(counters.events, o.segments + 1) << "photon " << i;
  }
  EXPECT_GT(ended, 10000);  // most photons end by roulette
}

// The file's ledger: exited + truncated + lost = launched on a white fiber,
// to rounding (absorbed is its complement).
TEST(Estimator, FileLedgerClosesOnWhiteFiber) {
  Settings s = testing::smooth_circle(30.0, 20000);
  s.estimator = Estimator::ExpectedValue;
  testing::make_rough(s, 10.0, 3.0);
  const ResultFile r = testing::run(s, 2);
  EXPECT_NEAR(r.absorbed[0], 0.0, 1e-9);
  EXPECT_NE(r.roulette[0], 0.0);  // roulette was played, and booked
}

// Russian roulette's term per photon (its rows' roulette, absorbed along
// the path to each), over 200,000 photons of an absorbing rough tilted
// ellipse: mean within 4 standard errors of 0 (the term is a sum of
// independent per-photon terms with expectation 0; 4 sigma: a false alarm
// once in ~16,000 runs of a fixed seed).
TEST(Estimator, RouletteTermHasExpectationZero) {
  Settings s = testing::smooth_circle(30.0, 1);
  s.estimator = Estimator::ExpectedValue;
  testing::make_rough(s, 10.0, 3.0);
  s.fiber.eccentricity = 0.8;
  const double sigma_a = 0.2;
  const Tracer tracer(s);
  const auto inc = s.incidences().front();
  constexpr int kPhotons = 200000;
  double sum = 0.0, sum_sq = 0.0;
  int played = 0;
  for (std::uint64_t i = 0; i < kPhotons; ++i) {
    LaunchedPhoton p = launch_photon(s.seed, i, inc.theta_i, inc.phi_i, false);
    const PhotonOutcome o = tracer.trace(p.wi, p.h, p.rng);
    double r = 0.0;
    for (const ScoredExitOutcome& e : o.scored) {
      r += e.roulette * std::exp(-sigma_a * e.path_length);
      played += e.roulette != 0.0;
    }
    sum += r;
    sum_sq += r * r;
  }
  const double mean = sum / kPhotons;
  const double se = std::sqrt((sum_sq / kPhotons - mean * mean) / (kPhotons - 1));
  std::printf("roulette played %d times; mean term %.3g, standard error %.3g\n", played, mean, se);
  EXPECT_GT(played, kPhotons / 10);
  EXPECT_LT(std::abs(mean), 4.0 * se);
}

TEST(Estimator, ErrorsMatchSpreadOverSeeds) {
  Settings s = testing::smooth_circle(30.0, 4000);
  s.estimator = Estimator::ExpectedValue;
  testing::make_rough(s, 10.0, 3.0);
  s.fiber.sigma_a = {0.3};
  // Coarse bins and three lobes: R, TT and p >= 2.
  s.tally.n_theta = 3;
  s.tally.n_phi = 2;
  s.tally.lobes = 3;
  expect_errors_match_spread(s, "3 lobes, 3 x 2 bins");
  // Two lobes, one bin: TT, TRT, TRRT, ... of each photon all add to the
  // last lobe's one bin, where the square of the photon's total differs
  // most from the sum of the squares of its parts.
  s.tally.n_theta = 1;
  s.tally.n_phi = 1;
  s.tally.lobes = 2;
  expect_errors_match_spread(s, "2 lobes, 1 bin");
}

TEST(Estimator, LobeErrorsMatchSpreadOverSeeds) {
  Settings s = testing::smooth_circle(30.0, 4000);
  testing::make_rough(s, 10.0, 3.0);
  s.fiber.sigma_a = {0.3};
  s.tally.n_theta = 12;
  s.tally.n_phi = 12;
  // R, TT and p >= 2; then R and p >= 1, where TT and TRT of one photon
  // (in different bins) share the last lobe: the cross term 2 t_TT t_TRT is
  // large against that lobe's small variance.
  for (const int lobes : {3, 2}) {
    s.tally.lobes = lobes;
    for (const Estimator e : {Estimator::Analog, Estimator::ExpectedValue}) {
      s.estimator = e;
      expect_lobe_errors_match_spread(s, (to_string(e) + ", " + std::to_string(lobes) + " lobes").c_str());
    }
  }
}

// The config key: a word of two, stored in config_yaml; an older file's
// config_yaml without it reads as analog (what wrote it).
TEST(Estimator, ConfigKey) {
  EXPECT_EQ(parse_settings_yaml("photons: 10\n", "t").estimator, Estimator::Analog);
  const Settings s = parse_settings_yaml("estimator: expected_value\n", "t");
  EXPECT_EQ(s.estimator, Estimator::ExpectedValue);
  EXPECT_EQ(parse_settings_yaml(to_yaml(s), "t"), s);
  EXPECT_EQ(parse_stored_settings_yaml(to_yaml(s), "t").estimator, Estimator::ExpectedValue);
  EXPECT_EQ(parse_stored_settings_yaml("photons: 10\n", "t").estimator, Estimator::Analog);
  try {
    parse_settings_yaml("estimator: roulette\n", "t");
    FAIL() << "estimator: roulette was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("estimator"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace fiberlab::sim
