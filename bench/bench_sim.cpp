// Photons per second per core for the reference cases (90 x 180
// bins, 8 lobes; the same cases as bench/configs/case_{a,b,c}.yaml, which time
// the whole process):
//  (a) smooth circle, sigma_a 0;
//  (b) circle, gaussian beta 5 deg, tilt 3 deg, sigma_a (0.2, 0.4, 0.8), theta_i 30 deg;
//  (c) ellipse e = 0.8, beta 7.5 deg, tilt 3 deg, the same sigma_a, theta_i 17, phi_i 11 deg;
//  (d) steep tilt: circle, beta 5 deg, tilt 20 deg, sigma_a 0, theta_i 30 deg (light
//      guided along the fiber runs to max_segments);
//  (g) case c with `ggx` alpha 0.19 (sqrt(2) tan 7.5 deg, the width
//      compare/models.cpp maps to beta 7.5 deg) instead of gaussian;
//  (k) the same with `beckmann` alpha 0.19;
//  (m) case c's geometry, white, `ggx` alpha 0.3 with `masking: smith_g1`.
// One thread, so the rate is per core. Counters: photons/s, interface events
// and candidate normals per photon. `trace_expected_value` runs b and c with
// `estimator: expected_value` (docs/PHYSICS.md "Estimator"), scoring included,
// and `trace_exit_splitting` the same with `exit_normals` (below). `trace` is the batched SIMD tracer that
// `fiberlab run` uses for unpolarised light (binning and tally included);
// `trace_reference` the scalar reference tracer (tracing only).
//
// `write`: one direction's result file (`fiberlab run`'s last step: the
// tally converted to float64 and exact pairs, deflated, written, renamed
// into place) from case c's tally after 1 M photons, on 1 and 2 threads.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <string>
#include <utility>
#include <vector>
#include <unistd.h>

#include "common/units.h"
#include "sim/store/checkpoint.h"
#include "sim/store/result_stream.h"
#include "sim/run/simulation.h"
#include "sim/life/source.h"

namespace {

using namespace fiberlab;
using namespace fiberlab::sim;

Settings bench_case(char which) {
  Settings s;
  s.seed = 1;
  s.fiber.eta = 1.55;
  s.tally.n_theta = 90;
  s.tally.n_phi = 180;
  s.tally.lobes = 8;
  if (which == 'a') {
    s.fiber.sigma_a = {0.0};
    s.fiber.roughness = fiberlab::roughness::Smooth{};
    s.source.theta_i = {deg_to_rad(30.0)};
    return s;
  }
  s.fiber.sigma_a = {0.2, 0.4, 0.8};
  s.fiber.scale_tilt = deg_to_rad(3.0);
  const double beta = deg_to_rad(which == 'c' ? 7.5 : 5.0);
  s.fiber.roughness = fiberlab::roughness::Gaussian{beta, beta};
  s.source.theta_i = {deg_to_rad(which == 'c' ? 17.0 : 30.0)};
  s.source.phi_i = {deg_to_rad(which == 'c' ? 11.0 : 0.0)};
  if (which == 'c') s.fiber.eccentricity = 0.8;
  if (which == 'd') {
    s.fiber.sigma_a = {0.0};
    s.fiber.scale_tilt = deg_to_rad(20.0);
  }
  if (which == 'g' || which == 'k' || which == 'm') {
    s.fiber.eccentricity = 0.8;
    s.source.theta_i = {deg_to_rad(17.0)};
    s.source.phi_i = {deg_to_rad(11.0)};
    const double alpha = which == 'm' ? 0.3 : 0.19;
    const fiberlab::Masking masking = which == 'm' ? fiberlab::Masking::SmithG1 : fiberlab::Masking::None;
    if (which == 'k') s.fiber.roughness = fiberlab::roughness::Beckmann{{alpha, alpha, masking}};
    else s.fiber.roughness = fiberlab::roughness::Ggx{{alpha, alpha, masking}};
    if (which == 'm') s.fiber.sigma_a = {0.0};
  }
  return s;
}

// `batch`: photons per call of the tracer (0: 65536, 2048 for case d). Each
// call ends with its lane pool draining; `run` makes one call per thread and
// round, fed runs of chunks of 4096 (sim/life/photon_feed.h), so it drains less
// often than here; trace_per_chunk shows one chunk per call.
void trace(benchmark::State& state, char which, std::uint64_t batch = 0,
           Estimator estimator = Estimator::Analog, std::vector<int> exit_normals = {1}) {
  Settings settings = bench_case(which);
  settings.estimator = estimator;
  settings.exit_normals = std::move(exit_normals);
  const Simulation sim(settings);
  if (batch == 0) batch = which == 'd' ? 2048 : 65536;
  Tally tally(8, 90, 180, static_cast<int>(sim.settings().fiber.sigma_a.size()));
  TracerCounters counters;
  std::uint64_t first = 0;
  for (auto _ : state) {
    sim.trace_photons(0, first, batch, tally, counters);
    first += batch;
  }
  const double photons = static_cast<double>(first);
  state.counters["photons_per_s"] = benchmark::Counter(photons, benchmark::Counter::kIsRate);
  state.counters["events_per_photon"] = counters.events / photons;
  state.counters["normals_per_photon"] = counters.normal_draws / photons;
  state.counters["truncated_fraction"] = tally.truncated()[0] / photons;
}

// The reference (scalar, one photon at a time) tracer on the same cases, for
// comparison; it is the one `polarization: stokes` uses.
void trace_reference(benchmark::State& state, char which) {
  const Settings s = bench_case(which);
  const Tracer tracer(s);
  const Source source(s.seed, s.source.theta_i[0], s.source.phi_i[0], false);
  TracerCounters counters;
  std::uint64_t photon = 0;
  double sink = 0.0;
  for (auto _ : state) {
    for (int k = 0; k < (which == 'd' ? 256 : 4096); ++k) {
      LaunchedPhoton p = source.launch(photon++);
      sink += tracer.trace(p.wi, p.h, p.rng, &counters).path_length;
    }
  }
  benchmark::DoNotOptimize(sink);
  state.counters["photons_per_s"] =
      benchmark::Counter(static_cast<double>(photon), benchmark::Counter::kIsRate);
}

BENCHMARK_CAPTURE(trace, a_smooth_circle, 'a')->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK_CAPTURE(trace, b_rough_tilted_circle, 'b')->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK_CAPTURE(trace, c_rough_tilted_ellipse, 'c')->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK_CAPTURE(trace, d_steep_tilt, 'd')->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK_CAPTURE(trace, g_ggx_ellipse, 'g')->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK_CAPTURE(trace, k_beckmann_ellipse, 'k')->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK_CAPTURE(trace, m_ggx_smith_g1_white, 'm')->Unit(benchmark::kMillisecond)->MinTime(2.0);
void trace_expected_value(benchmark::State& state, char which) {
  trace(state, which, 0, Estimator::ExpectedValue);
}
BENCHMARK_CAPTURE(trace_expected_value, b_rough_tilted_circle, 'b')->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK_CAPTURE(trace_expected_value, c_rough_tilted_ellipse, 'c')->Unit(benchmark::kMillisecond)->MinTime(2.0);
// Exit splitting (docs/PHYSICS.md "Exit splitting") at the settings aimed
// at one lobe: R on case c (exit_normals [16, 1]), TRT on case b ([1, 1, 16,
// 1]). Against trace_expected_value on the same case, the time per photon
// grows by (extra normals per photon) x (the cost of an extra normal: its
// draw and Fresnel term, and its row for the scorer).
void trace_exit_splitting(benchmark::State& state, char which, std::vector<int> exit_normals) {
  trace(state, which, 0, Estimator::ExpectedValue, std::move(exit_normals));
}
BENCHMARK_CAPTURE(trace_exit_splitting, c_R_16, 'c', std::vector<int>{16, 1})
    ->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK_CAPTURE(trace_exit_splitting, b_TRT_16, 'b', std::vector<int>{1, 1, 16, 1})
    ->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK_CAPTURE(trace, b_per_chunk, 'b', Simulation::kChunk)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK_CAPTURE(trace, c_per_chunk, 'c', Simulation::kChunk)->Unit(benchmark::kMillisecond)->MinTime(2.0);

void write(benchmark::State& state) {
  Settings s = bench_case('c');
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("fiberlab_bench_write_" + std::to_string(getpid()) + ".h5"))
                               .string();
  s.output = path;
  const Simulation sim(s);
  Tally tally(8, 90, 180, 3);
  TracerCounters counters;
  sim.trace_photons(0, 0, 1 << 20, tally, counters);
  const ResultFile header = result_header(sim.settings(), sim.grid());
  for (auto _ : state) {
    ResultWriter w(path, header);
    w.set_compression_threads(static_cast<int>(state.range(0)));
    w.write(0, tally);
    w.commit();
  }
  std::filesystem::remove(path);
}

BENCHMARK(write)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);

BENCHMARK_CAPTURE(trace_reference, a_smooth_circle, 'a')->Unit(benchmark::kMillisecond)->MinTime(1.0);
BENCHMARK_CAPTURE(trace_reference, b_rough_tilted_circle, 'b')->Unit(benchmark::kMillisecond)->MinTime(1.0);
BENCHMARK_CAPTURE(trace_reference, c_rough_tilted_ellipse, 'c')->Unit(benchmark::kMillisecond)->MinTime(1.0);
BENCHMARK_CAPTURE(trace_reference, d_steep_tilt, 'd')->Unit(benchmark::kMillisecond)->MinTime(1.0);
BENCHMARK_CAPTURE(trace_reference, g_ggx_ellipse, 'g')->Unit(benchmark::kMillisecond)->MinTime(1.0);
BENCHMARK_CAPTURE(trace_reference, k_beckmann_ellipse, 'k')->Unit(benchmark::kMillisecond)->MinTime(1.0);

}  // namespace

// The vector instructions the tracer was built for (and so the lanes per
// vector), in the context block, because the rates differ by about 2x
// between machines with AVX-512 (8 doubles a vector) and AVX2 (4).
int main(int argc, char** argv) {
  benchmark::AddCustomContext("simd", std::string(xsimd::default_arch::name()) + ", " +
                                          std::to_string(kBatchWidth) + " doubles a vector");
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
