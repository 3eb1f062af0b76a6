// Speed of the analytic models: S (density) evaluations per second and one
// full 90 x 180 x 4-lobe bin prediction (what `fiberlab predict` does per
// incident configuration).
#include <benchmark/benchmark.h>

#include <memory>
#include <string>
#include <vector>

#include "analytic/deon2011.h"
#include "analytic/huang2022.h"
#include "analytic/marschner2003.h"
#include "analytic/model_registry.h"
#include "analytic/smooth_cylinder.h"
#include "common/bin_grid.h"
#include "common/units.h"

using namespace fiberlab;
using namespace fiberlab::analytic;

namespace {

// The same rough, absorbing, tilted fiber in each model's own parameters.
ModelParameters typical(const std::string& name) {
  const std::vector<double> sigma_a{0.2, 0.4, 0.8};
  const std::vector<double> beta_long{deg_to_rad(5.0), deg_to_rad(2.5), deg_to_rad(10.0)};
  const std::vector<double> alpha{deg_to_rad(-6.0), deg_to_rad(3.0), deg_to_rad(12.0), 0.0};
  if (name == "deon2011") {
    Deon2011Params p;
    p.sigma_a = sigma_a;
    p.beta_long = beta_long;
    p.beta_azim = {deg_to_rad(5.0)};
    p.alpha = alpha;
    return ModelParameters(p);
  }
  if (name == "marschner2003") {
    Marschner2003Params p;
    p.sigma_a = sigma_a;
    p.beta_long = beta_long;
    p.alpha = alpha;
    return ModelParameters(p);
  }
  ExactParams p;
  p.sigma_a = sigma_a;
  return ModelParameters(p);
}

const char* kNames[] = {"exact", "deon2011", "marschner2003"};

void BM_Density(benchmark::State& state) {
  const std::string name = kNames[state.range(0)];
  const auto model = make_model(name, typical(name));
  std::vector<double> out;
  double tr = -0.5, phi = -3.0;
  const double ti = name == "exact" ? 0.5 : 0.4;
  for (auto _ : state) {
    for (int lobe = 0; lobe < 4; ++lobe) {
      model->density(lobe, ti, 0.0, name == "exact" ? -ti : tr, phi, out);
      benchmark::DoNotOptimize(out.data());
    }
    tr = tr > 0.5 ? -0.5 : tr + 0.013;
    phi = phi > 3.0 ? -3.0 : phi + 0.031;
  }
  state.SetItemsProcessed(state.iterations());  // one S = sum over the 4 lobes
  state.SetLabel(name);
}
BENCHMARK(BM_Density)->DenseRange(0, 2)->Unit(benchmark::kMicrosecond);

void BM_FullPredict(benchmark::State& state) {
  const std::string name = kNames[state.range(0)];
  const auto model = make_model(name, typical(name));
  const BinGrid grid = BinGrid::make(90, 180, ThetaBinning::Uniform);
  for (auto _ : state) {
    auto p = model->bin_probabilities(grid, deg_to_rad(30.5), 0.0);
    benchmark::DoNotOptimize(p.data());
  }
  state.SetLabel(name + " 90x180x4x3");
}
BENCHMARK(BM_FullPredict)->DenseRange(0, 2)->Unit(benchmark::kMillisecond)->Iterations(2);

// huang2022's push-forward (its cost is linear in quadrature_points) beside
// the exact model on the same 18 x 36 grid: one
// incidence, 2^18 points, the atlas's white ggx 0.3 fiber with a 3 deg tilt.
void BM_Huang2022Bins(benchmark::State& state) {
  Huang2022Params h;
  h.sigma_a = {0.0};
  h.roughness = 0.3;
  h.tilt = deg_to_rad(3.0);
  h.quadrature_points = 262144;
  ExactParams e;
  e.sigma_a = {0.0};
  const auto model = state.range(0) ? make_model("huang2022", ModelParameters(h)) : make_model("exact", ModelParameters(e));
  const BinGrid grid = BinGrid::make(18, 36, ThetaBinning::Uniform);
  for (auto _ : state) {
    auto b = model->bin_probabilities(grid, deg_to_rad(30.0), 0.0);
    benchmark::DoNotOptimize(b.data());
  }
  state.SetLabel(state.range(0) ? "huang2022 2^18 points, 18x36" : "exact, 18x36");
}
BENCHMARK(BM_Huang2022Bins)->DenseRange(0, 1)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
