// SPEC section 6: the same config and seed give bit-identical tallies for any
// number of threads; merging runs with two seeds adds them exactly.
#include <gtest/gtest.h>

#include <filesystem>

#include "common/error.h"

#include "tests/sim/sim_test_support.h"

namespace fiberlab::sim {
namespace {

Settings rough_absorbing() {
  Settings s = testing::smooth_circle(31.0, 60000);
  s.fiber.eccentricity = 0.9;
  s.fiber.sigma_a = {0.2, 0.4, 0.8};
  testing::make_rough(s, 5.0, 3.0);
  s.source.theta_i = {deg_to_rad(31.0), deg_to_rad(-12.0)};
  s.source.phi_i = {deg_to_rad(11.0)};
  return s;
}

TEST(Reproducibility, BitIdenticalForAnyThreadCount) {
  const Settings s = rough_absorbing();
  const ResultFile one = testing::run(s, 1);
  for (int threads : {2, 4}) {
    const ResultFile many = testing::run(s, threads);
    EXPECT_EQ(one.weight_sum, many.weight_sum) << threads << " threads";
    EXPECT_EQ(one.weight_sq_sum, many.weight_sq_sum) << threads << " threads";
    EXPECT_EQ(one.count, many.count) << threads << " threads";
    EXPECT_EQ(one.exited, many.exited);
    EXPECT_EQ(one.absorbed, many.absorbed);
    EXPECT_EQ(one.truncated, many.truncated);
  }
}

// Streams are keyed by the incident direction's value, not its place in the
// sweep: a sweep split into jobs gives, direction by direction, the same
// tallies as one run (what merging split sweeps relies on).
TEST(Reproducibility, SplitSweepEqualsOneRun) {
  for (bool uniform : {false, true}) {
    Settings s = rough_absorbing();
    s.source.phi_i_uniform = uniform;
    const ResultFile whole = testing::run(s);
    Settings part = s;
    part.source.theta_i = {s.source.theta_i[1]};
    const ResultFile second = testing::run(part);
    const std::size_t per_k = whole.weight_sum.size() / 2;
    const std::vector<double> tail(whole.weight_sum.begin() + per_k, whole.weight_sum.end());
    EXPECT_EQ(tail, second.weight_sum) << (uniform ? "phi_i uniform" : "fixed phi_i");
    EXPECT_EQ(whole.truncated[1 * 3 + 0], second.truncated[0]);
    // And the first direction's photons are not the second's.
    const std::vector<double> head(whole.weight_sum.begin(), whole.weight_sum.begin() + per_k);
    EXPECT_NE(head, second.weight_sum);
  }
}

TEST(Reproducibility, DifferentSeedsDiffer) {
  Settings s = rough_absorbing();
  const ResultFile a = testing::run(s);
  s.seed += 1;
  EXPECT_NE(a.weight_sum, testing::run(s).weight_sum);
}

TEST(Reproducibility, MergeOfTwoSeedsIsTheSumAndRoundTripsThroughHdf5) {
  Settings s = rough_absorbing();
  const auto dir = std::filesystem::temp_directory_path() / "fiberlab_test_merge";
  std::filesystem::create_directories(dir);
  const std::string pa = (dir / "a.h5").string(), pb = (dir / "b.h5").string();
  const ResultFile a = testing::run(s);
  s.seed = 999;
  const ResultFile b = testing::run(s);
  write_result(a, pa);
  write_result(b, pb);
  const ResultFile ra = read_result(pa), rb = read_result(pb);
  EXPECT_EQ(ra.weight_sum, a.weight_sum);  // HDF5 round trip is exact
  EXPECT_EQ(ra.count, a.count);
  const ResultFile m = merge_results({ra, rb}, {pa, pb});
  for (std::size_t i = 0; i < m.weight_sum.size(); ++i) {
    ASSERT_EQ(m.weight_sum[i], a.weight_sum[i] + b.weight_sum[i]);
    ASSERT_EQ(m.weight_sq_sum[i], a.weight_sq_sum[i] + b.weight_sq_sum[i]);
  }
  for (std::size_t i = 0; i < m.count.size(); ++i) ASSERT_EQ(m.count[i], a.count[i] + b.count[i]);
  EXPECT_EQ(m.photons[0], a.photons[0] + b.photons[0]);
  EXPECT_EQ(m.seeds, (std::vector<std::uint64_t>{s.seed == 999 ? a.seeds[0] : 0, 999}));
  // Merging a run with itself (same seed), or with a different fiber, is refused.
  EXPECT_THROW(merge_results({ra, ra}, {pa, pa}), Error);
  Settings other = rough_absorbing();
  other.fiber.eta = 1.5;
  other.seed = 7;
  EXPECT_THROW(merge_results({ra, testing::run(other)}, {pa, "other"}), Error);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace fiberlab::sim
