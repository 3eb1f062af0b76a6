// Stratified impact parameters (sim/life/source.h, SPEC section 5; opt-in with
// `source.h_sampling: stratified`): which stratum each photon's h falls in,
// that photons outside full blocks and runs with `source.h_sampling:
// independent` (the default) draw h exactly as 2u - 1, that the batched
// tracer launches the same h as the Source, and the config key.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "common/error.h"
#include "sim/life/batch_tracer.h"
#include "sim/life/source.h"
#include "tests/sim/sim_test_support.h"

namespace fiberlab::sim {
namespace {

constexpr std::uint64_t M = Source::kStrata;

std::uint64_t stratum_of(double h) { return static_cast<std::uint64_t>(std::floor((h + 1.0) / 2.0 * M)); }

TEST(StratifiedH, FullBlocksHitEveryStratumOnceTheRestIsIndependent) {
  const std::uint64_t photons = 2 * M + 1000;  // two full blocks, one partial
  const Source strat(7, 0.5, 0.1, false, photons);
  const Source plain(7, 0.5, 0.1, false);
  for (std::uint64_t block = 0; block < 2; ++block) {
    std::vector<int> hits(M, 0);
    for (std::uint64_t j = 0; j < M; ++j) {
      const double h = strat.launch(block * M + j).h;
      ASSERT_GE(h, -1.0);
      ASSERT_LT(h, 1.0);
      ++hits[stratum_of(h)];
      // The photon's own stratum, in photon order.
      EXPECT_EQ(stratum_of(h), j) << "photon " << block * M + j;
    }
    for (std::uint64_t s = 0; s < M; ++s) ASSERT_EQ(hits[s], 1) << "stratum " << s;
  }
  // The partial block: the h of independent sampling, bit for bit.
  for (std::uint64_t i = 2 * M; i < photons; ++i) EXPECT_EQ(strat.launch(i).h, plain.launch(i).h);
  // Independent sampling is 2u - 1 of the photon's first draw.
  for (std::uint64_t i = 0; i < 100; ++i) {
    PhotonRandom rng(plain.stream_key(), i);
    EXPECT_EQ(plain.launch(i).h, 2.0 * rng.uniform() - 1.0);
  }
}

TEST(StratifiedH, HNeverReachesOneAndKeepsTheDrawsFineBits) {
  const Source strat(1, 0.0, 0.0, false, M);
  const double top = strat.impact_parameter(M - 1, 1.0 - 0x1.0p-53);
  EXPECT_LT(top, 1.0);
  EXPECT_EQ(strat.impact_parameter(0, 0.0), -1.0);
  // Within a stratum h moves with u (41 bits of it).
  EXPECT_LT(strat.impact_parameter(5, 0.25), strat.impact_parameter(5, 0.75));
  EXPECT_EQ(stratum_of(strat.impact_parameter(5, 0.999)), 5u);
}

TEST(StratifiedH, BatchedTracerLaunchesTheSourcesH) {
  // Photon by photon against the reference tracer fed by the run's Source:
  // the same fate, segments and path (as in test_batch_tracer.cpp) only if
  // both used the same stratified h.
  Settings s = testing::smooth_circle(37.0, 3 * M);
  s.fiber.eccentricity = 0.8;
  s.source.h_stratified = true;
  const Tracer reference(s);
  const BatchTracer batch(s);
  const auto inc = s.incidences().front();
  const Source source(s, inc.theta_i, inc.phi_i);
  std::vector<PhotonOutcome> out(s.photons);
  TracerCounters counters;
  batch.trace(inc.theta_i, inc.phi_i, 0, s.photons,
              [&](const FinishedPhotons& f) {
                for (int j = 0; j < f.n; ++j) out[f.photon[j]] = f.outcome(j);
              },
              counters);
  int differ = 0;
  for (std::uint64_t i = 0; i < s.photons; ++i) {
    LaunchedPhoton p = source.launch(i);
    const PhotonOutcome r = reference.trace(p.wi, p.h, p.rng);
    differ += r.fate != out[i].fate || r.segments != out[i].segments ||
              std::abs(r.path_length - out[i].path_length) > 1e-7 * (1.0 + r.path_length);
  }
  EXPECT_LE(differ, static_cast<int>(s.photons / 1000));
}

TEST(StratifiedH, ConfigKeyDefaultRoundTripAndErrors) {
  EXPECT_FALSE(parse_settings_yaml("{}", "t.yaml").source.h_stratified);
  const Settings on = parse_settings_yaml("source: {h_sampling: stratified}\n", "t.yaml");
  EXPECT_TRUE(on.source.h_stratified);
  EXPECT_EQ(parse_settings_yaml(to_yaml(on), "t.yaml"), on);
  const Settings off = parse_settings_yaml("source: {h_sampling: independent}\n", "t.yaml");
  EXPECT_FALSE(off.source.h_stratified);
  EXPECT_EQ(parse_settings_yaml(to_yaml(off), "t.yaml"), off);
  try {
    parse_settings_yaml("source: {h_sampling: sobol}\n", "t.yaml");
    FAIL() << "accepted h_sampling: sobol";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("source.h_sampling"), std::string::npos) << m;
    EXPECT_NE(m.find("independent"), std::string::npos) << m;
  }
}

// The stratified estimator against SPEC section 8's exact lobe energies
// (smooth circle, 60 deg; the photons are not a multiple of kStrata, so the
// last partial block is drawn independently), and the same bits for any
// number of threads.
TEST(StratifiedH, SmoothCircleEnergiesMatchSpecSection8ForAnyThreadCount) {
  Settings s = testing::smooth_circle(60.0, 500000);
  s.source.h_stratified = true;
  const double known[4] = {0.17347, 0.69735, 0.10201, 0.02717};  // SPEC section 8
  const ResultFile r = testing::run(s, 3);
  for (int lobe = 0; lobe < 4; ++lobe) {
    const Estimate e = lobe_energy(r, 0, lobe, 0);
    EXPECT_NEAR(e.mean, known[lobe], 4.0 * e.std_error) << "lobe " << lobe;
  }
  const ResultFile one = testing::run(s, 1);
  EXPECT_EQ(one.weight_sum, r.weight_sum);
  EXPECT_EQ(one.weight_sq_sum, r.weight_sq_sum);
  EXPECT_EQ(one.count, r.count);
}

}  // namespace
}  // namespace fiberlab::sim
