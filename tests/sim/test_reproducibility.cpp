// SPEC section 6: the same config and seed give bit-identical tallies for any
// number of threads; merging runs with two seeds adds them exactly.
#include <gtest/gtest.h>

#include <filesystem>

#include "common/error.h"
#include "sim/store/checkpoint.h"
#include "sim/store/merge.h"
#include "sim/store/result_stream.h"

#include "tests/sim/sim_test_support.h"
#include "tests/unique_temp_dir.h"

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

TEST(Reproducibility, MergeOfTwoSeedsIsTheExactSumAndRoundTripsThroughHdf5) {
  Settings s = rough_absorbing();
  const auto dir = test_support::unique_temp_dir("fiberlab_test_merge");
  const std::string pa = (dir / "a.h5").string(), pb = (dir / "b.h5").string();
  const std::string pm = (dir / "m.h5").string(), other_path = (dir / "o.h5").string();
  auto run_to = [](const Settings& settings, const std::string& path) {
    const Simulation sim(settings);
    std::vector<ExactTally> exact;
    for (const Tally& t : sim.run(2)) exact.push_back(t.exact());
    write_result_exact(path, result_header(settings, sim.grid()), exact);
    return exact;
  };
  const std::vector<ExactTally> a = run_to(s, pa);
  s.seed = 999;
  const std::vector<ExactTally> b = run_to(s, pb);
  const ResultFile ra = read_result(pa);
  const std::vector<double> first(ra.weight_sum.begin(), ra.weight_sum.begin() + ra.bin_cells());
  EXPECT_EQ(first, ExactTally::to_double(a[0].weight_sum));  // float64 = exact / 2^60
  merge_result_files({pa, pb}, pm);
  const ResultReader m(pm);
  ASSERT_EQ(m.header().theta_i.size(), a.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    // The merged file lists directions by increasing theta_i.
    const std::size_t i = m.header().theta_i[k] == ra.theta_i[0] ? 0 : 1;
    ASSERT_EQ(m.header().theta_i[k], ra.theta_i[i]);
    ExactTally sum = a[i];
    sum += b[i];
    const ExactTally got = m.read(k);
    EXPECT_TRUE(got.weight_sum == sum.weight_sum);
    EXPECT_TRUE(got.weight_sq_sum == sum.weight_sq_sum);
    EXPECT_EQ(got.count, sum.count);
    EXPECT_EQ(got.photons, sum.photons);
  }
  EXPECT_EQ(m.header().seeds, (std::vector<std::uint64_t>{999, rough_absorbing().seed}));  // sorted
  // Merging a run with itself (same seed), or with a different fiber, is refused.
  EXPECT_THROW(merge_result_files({pa, pa}, (dir / "x.h5").string()), Error);
  Settings other = rough_absorbing();
  other.fiber.eta = 1.5;
  other.seed = 7;
  run_to(other, other_path);
  EXPECT_THROW(merge_result_files({pa, other_path}, (dir / "y.h5").string()), Error);
  EXPECT_FALSE(std::filesystem::exists(dir / "x.h5"));
  EXPECT_FALSE(std::filesystem::exists(dir / "y.h5"));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace fiberlab::sim
