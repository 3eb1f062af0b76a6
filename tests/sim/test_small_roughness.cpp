// Small gaussian roughness on a tilted fiber (SPEC section 3): beta 0 is the
// smooth model, fallback included, and for small beta the visible normals of
// a tilted normal facing away from the photon are drawn from the far tail
// exactly, so the sampler never truncates a photon.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "tests/sim/sim_test_support.h"

namespace fiberlab::sim {
namespace {

Settings tilted_circle_at_60(std::uint64_t photons) {
  Settings s = testing::smooth_circle(60.0, photons);
  s.fiber.scale_tilt = deg_to_rad(3.0);
  return s;
}

TEST(SmallRoughness, BetaZeroIsTheSmoothModelBitForBit) {
  const Settings smooth = tilted_circle_at_60(200000);
  Settings rough = smooth;
  testing::make_rough(rough, 0.0, 3.0);
  const ResultFile a = testing::run(smooth), b = testing::run(rough);
  EXPECT_EQ(a.weight_sum, b.weight_sum);
  EXPECT_EQ(a.count, b.count);
  EXPECT_EQ(a.truncated, b.truncated);
  EXPECT_EQ(b.truncated[0], 0.0);
}

// Tilt 3 deg, theta_i 60 deg, beta 0.5 deg. Near the fiber's edge
// (|h| > 0.9959, 0.41% of the photons) the tilted normal faces away from the
// incoming photon by up to 2.6 deg = 5.2 beta; plain rejection truncated
// 1.2% of the photons (internal events included) and put R 28 standard
// errors low.
//
// Oracle: the smooth tilted fiber (the beta -> 0 limit). The two differ by
// O(beta^2) = 8e-5 in the Fresnel averages, and on the 0.41% of edge photons,
// whose reflectance is 0.85-1 in both (grazing: the smooth model's
// untilted-normal fallback against a chain of grazing tail reflections):
// at most 0.0041 x 0.15 = 6e-4, about one standard error of the difference
// at 1e6 photons each. Accept |z| < 4.
TEST(SmallRoughness, FarTailSampledExactlyAtOneHalfDegree) {
  Settings rough = tilted_circle_at_60(1000000);
  testing::make_rough(rough, 0.5, 3.0);
  Settings smooth = tilted_circle_at_60(1000000);
  smooth.seed = 777;
  RunStatistics stats;
  const Simulation sim(rough);
  const ResultFile r = make_result(rough, sim.grid(), sim.run(2, {}, &stats));
  const ResultFile s = testing::run(smooth);
  EXPECT_EQ(stats.counters.sampler_caps, 0);
  const double N = 1e6;
  auto R_and_se = [&](const ResultFile& f) {
    const double e = f.exited[0] / N;  // weights are 0 or 1 (sigma_a = 0)
    return std::pair{e, std::sqrt(e * (1.0 - e) / (N - 1.0))};
  };
  const auto [rr, rse] = R_and_se(r);
  const auto [sr, sse] = R_and_se(s);
  const double z = (rr - sr) / std::hypot(rse, sse);
  std::printf("R: beta 0.5 deg %.6f +- %.6f, smooth %.6f +- %.6f, z = %.2f; truncated %.3g\n", rr,
              rse, sr, sse, z, r.truncated[0] / N);
  EXPECT_LT(std::abs(z), 4.0);
  EXPECT_EQ(r.truncated[0], 0.0);  // nothing guided either at this beta
}

}  // namespace
}  // namespace fiberlab::sim
