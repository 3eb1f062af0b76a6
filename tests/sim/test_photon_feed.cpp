// Runs of photons from a feed (sim/life/photon_feed.h): the batched tracer keeps
// its pool across runs, so it must trace every photon of every run exactly
// once, whatever the runs' sizes and order, and each photon exactly as it
// would alone (its path depends on its index only). Runs here are odd-sized,
// out of order and not adjacent, so lanes launched part-way through a vector
// and pools refilled from a new run are exercised.
#include <gtest/gtest.h>

#include <numeric>
#include <vector>

#include "sim/life/batch_tracer.h"
#include "sim/life/photon_feed.h"
#include "sim/life/source.h"
#include "tests/sim/sim_test_support.h"

namespace fiberlab::sim {
namespace {

// [0, 20011) cut into runs of 1 to ~5000 photons, handed out out of order,
// with an empty run from the feed only at its end.
std::vector<PhotonRun> scattered_runs() {
  return {{4000, 3},     {0, 5},         {5, 1},     {20000, 11}, {6, 3994},
          {4003, 4096},  {8099, 1},      {8100, 7},  {8107, 5},   {13000, 7000},
          {8112, 4888}};
}

PhotonFeed feed_of(std::vector<PhotonRun> runs) {
  return [runs = std::move(runs), i = std::size_t{0}]() mutable {
    return i < runs.size() ? runs[i++] : PhotonRun{};
  };
}

constexpr std::uint64_t kPhotons = 20011;

Settings rough_tilted_ellipse() {
  Settings s = testing::smooth_circle(17.0, kPhotons);
  s.fiber.eccentricity = 0.8;
  s.fiber.sigma_a = {0.2, 0.4, 0.8};
  testing::make_rough(s, 7.5, 3.0);
  s.source.phi_i = {deg_to_rad(11.0)};
  s.max_segments = 40;  // some photons truncated too
  return s;
}

std::vector<PhotonOutcome> trace_all(const BatchTracer& tracer, const Settings& s,
                                     const PhotonFeed& feed, std::vector<int>& seen) {
  const auto inc = s.incidences().front();
  std::vector<PhotonOutcome> out(kPhotons);
  seen.assign(kPhotons, 0);
  TracerCounters counters;
  tracer.trace(inc.theta_i, inc.phi_i, feed,
               [&](const FinishedPhotons& f) {
                 for (int j = 0; j < f.n; ++j) {
                   const std::uint64_t i = f.photon[j];
                   ASSERT_LT(i, kPhotons);
                   out[i] = f.outcome(j);
                   ++seen[i];
                 }
               },
               counters);
  return out;
}

TEST(PhotonFeed, ScatteredRunsTraceEachPhotonOnceAsASingleRunDoes) {
  const Settings s = rough_tilted_ellipse();
  const BatchTracer tracer(s);
  std::vector<int> seen_one, seen_fed;
  const auto one = trace_all(tracer, s, single_run(0, kPhotons), seen_one);
  const auto fed = trace_all(tracer, s, feed_of(scattered_runs()), seen_fed);
  int truncated = 0;
  for (std::uint64_t i = 0; i < kPhotons; ++i) {
    ASSERT_EQ(seen_one[i], 1) << "photon " << i;
    ASSERT_EQ(seen_fed[i], 1) << "photon " << i;
    // Bit for bit: every operation of the life is lane by lane.
    EXPECT_EQ(fed[i].fate, one[i].fate) << "photon " << i;
    EXPECT_EQ(fed[i].segments, one[i].segments) << "photon " << i;
    EXPECT_EQ(fed[i].path_length, one[i].path_length) << "photon " << i;
    EXPECT_EQ(fed[i].direction, one[i].direction) << "photon " << i;
    EXPECT_EQ(fed[i].weight, one[i].weight) << "photon " << i;
    truncated += one[i].fate == PhotonFate::Truncated;
  }
  EXPECT_GT(truncated, 0);  // the case exercises truncation as well as exits
}

// The same through Simulation::trace_photons: equal exact tallies, and the
// photons launched counted from the runs handed out.
TEST(PhotonFeed, SimulationTalliesOfScatteredRunsEqualOneRun) {
  Settings s = rough_tilted_ellipse();
  const Simulation sim(s);
  const TallyShape shape = sim.tally_shape();
  Tally one(shape.lobes, shape.n_theta, shape.n_phi, shape.channels);
  Tally fed(shape.lobes, shape.n_theta, shape.n_phi, shape.channels);
  TracerCounters counters;
  sim.trace_photons(0, 0, kPhotons, one, counters);
  sim.trace_photons(0, feed_of(scattered_runs()), fed, counters);
  EXPECT_EQ(one.photons(), kPhotons);
  EXPECT_EQ(fed.photons(), kPhotons);
  EXPECT_TRUE(one.exact().words() == fed.exact().words());
  // A microfacet model (its own sampler, and with masking a list of losses
  // per photon in flight) takes the runs as well.
  s.fiber.roughness = testing::microfacet(MicrofacetModel::GGX, 0.1, 0.1, Masking::SmithG1);
  const Simulation reference(s);
  Tally ref_one(shape.lobes, shape.n_theta, shape.n_phi, shape.channels);
  Tally ref_fed(shape.lobes, shape.n_theta, shape.n_phi, shape.channels);
  reference.trace_photons(0, 0, kPhotons, ref_one, counters);
  reference.trace_photons(0, feed_of(scattered_runs()), ref_fed, counters);
  EXPECT_EQ(ref_fed.photons(), kPhotons);
  EXPECT_TRUE(ref_one.exact().words() == ref_fed.exact().words());
  // Every exit scored: as many as the reference tracer finds photon by
  // photon, and every loss booked.
  const Tracer tracer(s);
  const auto inc = s.incidences().front();
  std::uint64_t exits = 0;
  for (std::uint64_t i = 0; i < kPhotons; ++i) {
    LaunchedPhoton p = launch_photon(s.seed, i, inc.theta_i, inc.phi_i, s.source.phi_i_uniform);
    exits += tracer.trace(p.wi, p.h, p.rng).fate == PhotonFate::Exited;
  }
  const std::vector<std::uint64_t> count = ref_fed.count();
  EXPECT_EQ(std::accumulate(count.begin(), count.end(), std::uint64_t{0}), exits);
  EXPECT_GT(ref_fed.lost()[0], 0.0);
}

TEST(PhotonFeed, SingleRunHandsOutItsRunOnceThenNothing) {
  const PhotonFeed feed = single_run(7, 3);
  const PhotonRun a = feed();
  EXPECT_EQ(a.first, 7u);
  EXPECT_EQ(a.n, 3u);
  EXPECT_EQ(feed().n, 0u);
  EXPECT_EQ(feed().n, 0u);
  EXPECT_EQ(single_run(7, 0)().n, 0u);
}

}  // namespace
}  // namespace fiberlab::sim
