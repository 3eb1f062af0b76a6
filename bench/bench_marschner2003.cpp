// Cost of the Marschner 2003 model (analytic/marschner2003.h): one density()
// call per lobe (cubic roots of Eq. 10 vs exact roots of Eq. 3, with and
// without the caustic procedure of section 5.2.2 and eccentricity), and a
// whole 90 x 180 bin_probabilities() for one incident configuration.
#include <benchmark/benchmark.h>

#include <vector>

#include "analytic/marschner2003.h"
#include "common/bin_grid.h"
#include "common/units.h"

namespace {

using namespace fiberlab;
using namespace fiberlab::analytic;

// Table 1 typical values: beta_R 7.5, beta_TT 3.75, beta_TRT 15 deg (as
// theta_h widths), alpha_R -7.5 deg of theta_h = -15 deg of theta_r.
Marschner2003Params bench_params(bool exact, bool glints, double eccentricity) {
  Marschner2003Params p;
  p.eta = 1.55;
  p.sigma_a = {0.2, 0.4, 0.8};
  p.beta_long = {deg_to_rad(7.5), deg_to_rad(3.75), deg_to_rad(15.0)};
  p.alpha = {deg_to_rad(-15.0), deg_to_rad(7.5), deg_to_rad(22.5)};
  p.exact_roots = exact;
  p.eccentricity = eccentricity;
  if (glints) {
    p.k_g = 0.5;
    p.w_c = deg_to_rad(15.0);
    p.delta_eta = 0.3;
    p.delta_h_m = 0.5;
  }
  return p;
}

void BM_Density(benchmark::State& state) {
  const bool exact = state.range(0) != 0, glints = state.range(1) != 0;
  const double ecc = state.range(2) != 0 ? 0.85 : 1.0;
  const auto model = make_marschner2003(bench_params(exact, glints, ecc));
  std::vector<double> out;
  double phi = -kPi, sink = 0.0;
  for (auto _ : state) {
    for (int lobe = 0; lobe < 3; ++lobe) {
      model->density(lobe, 0.5, 0.3, -0.45, phi, out);
      sink += out[0];
    }
    phi += 0.0123;
    if (phi >= kPi) phi -= kTwoPi;
  }
  benchmark::DoNotOptimize(sink);
  state.SetItemsProcessed(state.iterations() * 3);
}
BENCHMARK(BM_Density)
    ->ArgNames({"exact", "glints", "ecc"})
    ->Args({0, 0, 0})
    ->Args({1, 0, 0})
    ->Args({0, 1, 0})
    ->Args({1, 1, 0})
    ->Args({0, 1, 1});

void BM_BinProbabilities(benchmark::State& state) {
  const double ecc = state.range(1) != 0 ? 0.85 : 1.0;
  const auto model = make_marschner2003(bench_params(state.range(0) != 0, true, ecc));
  const BinGrid grid = BinGrid::make(90, 180, ThetaBinning::Uniform);
  for (auto _ : state) benchmark::DoNotOptimize(model->bin_probabilities(grid, 0.5, 0.0));
}
BENCHMARK(BM_BinProbabilities)
    ->ArgNames({"exact", "ecc"})
    ->Args({0, 0})
    ->Args({1, 0})
    ->Args({0, 1})
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
