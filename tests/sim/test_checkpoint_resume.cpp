// A run stopped after some whole chunks, saved to a checkpoint file,
// read back and continued gives the same bits as the run done in one go; the
// exact sums survive files and MPI's word format; the target-error measure
// agrees with the result file's lobe estimator (SPEC section 6).
#include <gtest/gtest.h>

#include <filesystem>

#include "common/error.h"
#include "sim/store/checkpoint.h"
#include "sim/store/exact_tally.h"
#include "sim/store/result_stream.h"
#include "tests/sim/sim_test_support.h"
#include "tests/unique_temp_dir.h"

namespace fiberlab::sim {
namespace {

Settings small_rough() {
  Settings s = testing::smooth_circle(27.0, 5 * Simulation::kChunk + 17);
  s.fiber.sigma_a = {0.3, 0.9};
  testing::make_rough(s, 6.0, 2.0);
  s.source.theta_i = {deg_to_rad(27.0), deg_to_rad(-41.0)};
  s.tally.n_theta = 12;
  s.tally.n_phi = 24;
  return s;
}

void expect_same(const ExactTally& a, const ExactTally& b) {
  EXPECT_EQ(a.photons, b.photons);
  EXPECT_EQ(a.count, b.count);
  EXPECT_TRUE(a.weight_sum == b.weight_sum);
  EXPECT_TRUE(a.weight_sq_sum == b.weight_sq_sum);
  EXPECT_TRUE(a.exited == b.exited);
  EXPECT_TRUE(a.absorbed == b.absorbed);
  EXPECT_TRUE(a.truncated == b.truncated);
}

TEST(CheckpointResume, StoppedSavedReadAndContinuedEqualsOneGo) {
  const Settings s = small_rough();
  const Simulation whole(s);
  const std::vector<Tally> reference = whole.run(2);

  // The first 3 chunks of every direction: a run of fewer photons.
  Settings part = s;
  part.photons = 3 * Simulation::kChunk;
  const Simulation first(part);
  RunProgress state = first.start();
  RunControl control;
  control.threads = 1;
  ASSERT_EQ(first.run(state, control), RunOutcome::Finished);
  state.done.assign(state.done.size(), 0);  // not finished at s.photons

  const auto dir = test_support::unique_temp_dir("fiberlab_test_checkpoint");
  const std::string path = (dir / "run.checkpoint.h5").string();
  write_checkpoint(path, whole, state, 0.0);
  Checkpoint saved = read_checkpoint(path, true);
  EXPECT_EQ(saved.settings, s);
  EXPECT_EQ(saved.state.next_photon, state.next_photon);

  control.threads = 3;
  ASSERT_EQ(whole.run(saved.state, control), RunOutcome::Finished);
  for (std::size_t k = 0; k < reference.size(); ++k)
    expect_same(saved.state.tallies[k].exact(), reference[k].exact());
  std::filesystem::remove_all(dir);
}

TEST(CheckpointResume, CheckpointOfAnotherConfigIsRefused) {
  const Settings s = small_rough();
  const Simulation sim(s);
  const auto dir = test_support::unique_temp_dir("fiberlab_test_checkpoint_cfg");
  const std::string path = (dir / "c.checkpoint.h5").string();
  write_checkpoint(path, sim, sim.start(), 0.0);
  const Checkpoint c = read_checkpoint(path, false);
  Settings other = s;
  other.fiber.eta = 1.56;
  EXPECT_THROW(check_same_config(c, other, path), Error);
  EXPECT_NO_THROW(check_same_config(c, s, path));
  std::filesystem::remove_all(dir);
}

TEST(ExactTally, WordsAndPairsRoundTripAbove64Bits) {
  ExactTally t({2, 1, 1, 2});
  t.photons = 7;
  t.count = {3, 4};
  t.weight_sum = {(ExactTally::Word{1} << 100) + 5, 1, 2, ExactTally::Word{~0ull} + 1};
  t.weight_sq_sum = {9, 8, 7, 6};
  t.exited = {1, 2, 3, 4};
  t.absorbed = {ExactTally::Word{1} << 70, 0};
  t.truncated = {0, 1};
  ExactTally u(t.shape);
  u.from_words(t.words());
  expect_same(t, u);
  EXPECT_TRUE(ExactTally::from_pairs(ExactTally::to_pairs(t.weight_sum)) == t.weight_sum);
  u += t;
  EXPECT_EQ(u.photons, 14u);
  EXPECT_TRUE(u.weight_sum[0] == 2 * t.weight_sum[0]);
}

TEST(ExactTally, TallyExactMatchesItsFloatOutput) {
  const Settings s = small_rough();
  const std::vector<Tally> tallies = Simulation(s).run(2);
  for (const Tally& t : tallies) {
    const ExactTally e = t.exact();
    EXPECT_EQ(ExactTally::to_double(e.weight_sum), t.weight_sum());
    EXPECT_EQ(ExactTally::to_double(e.weight_sq_sum), t.weight_sq_sum());
    EXPECT_EQ(ExactTally::to_double(e.exited), t.exited());
    EXPECT_EQ(ExactTally::to_double(e.absorbed), t.absorbed());
    EXPECT_EQ(e.count, t.count());
  }
}

TEST(TargetError, LargestRelativeErrorIsTheWorstLobeOfTheResultEstimator) {
  const Settings s = small_rough();
  const ResultFile r = testing::run(s);
  const std::vector<Tally> tallies = Simulation(s).run(1);
  for (std::size_t k = 0; k < r.configs(); ++k) {
    double worst = 0.0;
    for (int l = 0; l < r.lobes; ++l)
      for (int c = 0; c < r.channels; ++c) {
        const Estimate e = lobe_energy(r, k, l, c);
        if (e.mean > 0) worst = std::max(worst, e.std_error / e.mean);
      }
    EXPECT_NEAR(Simulation::largest_relative_error(tallies[k].exact()), worst, 1e-12 * worst);
  }
}

}  // namespace
}  // namespace fiberlab::sim
