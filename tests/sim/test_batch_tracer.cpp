// The batched, vectorised tracer against the reference tracer, photon by
// photon: each photon draws from its own stream in the same order in both,
// so paths agree to rounding (drift(): the drift of light-guided photons,
// whose paths past ~50 segments are judged apart), except where the two round differently in the
// last bit and that flips a random decision (rare: the sampler's sin, cos
// and log are one code for both, sim/simd/life_trig.h and sim/simd/life_log.h, but the
// compiler may fuse a product into a sum in one form and not the other).
#include <gtest/gtest.h>

#include <cstdio>
#include <map>
#include <string>

#include "sim/life/batch_tracer.h"
#include "sim/life/source.h"
#include "tests/sim/sim_test_support.h"

namespace fiberlab::sim {
namespace {

// What the last-bit drift of a path after `segments` segments may move a
// direction or a weight by (about 1e-8 per segment on light-guided paths;
// expected-value scoring follows many more of them to their end than the
// analog estimator, whose photons mostly leave at TT).
double drift(int segments) { return 1e-7 * (1.0 + segments); }

// The exits two tracers scored by expected value for one photon, to rounding.
bool same_scored(const std::vector<ScoredExitOutcome>& a, const std::vector<ScoredExitOutcome>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t k = 0; k < a.size(); ++k)
    if (a[k].segments != b[k].segments ||
        (a[k].direction - b[k].direction).norm() > drift(a[k].segments) ||
        std::abs(a[k].path_length - b[k].path_length) > 1e-7 * (1.0 + a[k].path_length) ||
        std::abs(a[k].weight - b[k].weight) > drift(a[k].segments))
      return false;
  return true;
}

void expect_same_photons_with(const Settings& s, const std::string& what_estimator) {
  const char* what = what_estimator.c_str();
  const std::uint64_t n = 50000;
  const Tracer reference(s);
  const BatchTracer batch(s);
  const auto inc = s.incidences().front();
  std::vector<PhotonOutcome> batched(n);
  std::vector<double> batched_phi(n);
  std::vector<int> seen(n, 0);
  // Exits scored by expected value on the way (rows before a photon's last).
  std::vector<std::vector<ScoredExitOutcome>> scored(n);
  TracerCounters counters;
  batch.trace(inc.theta_i, inc.phi_i, 0, n,
              [&](const FinishedPhotons& f) {
                for (int j = 0; j < f.n; ++j) {
                  const std::uint64_t i = f.photon[j];
                  if (!f.last[j]) {
                    scored[i].push_back({Vec3(f.dx[j], f.dy[j], f.dz[j]), f.segments[j], f.path[j],
                                         f.weight[j]});
                    continue;
                  }
                  batched[i] = f.outcome(j);
                  batched_phi[i] = f.phi_i[j];
                  ++seen[i];
                }
              },
              counters);
  int differ = 0, long_paths = 0, long_differ = 0;
  constexpr int kLongPath = 50;
  double diverged_segments = 0.0;  // over photons whose paths came apart
  TracerCounters reference_counters;
  for (std::uint64_t i = 0; i < n; ++i) {
    ASSERT_EQ(seen[i], 1) << "photon " << i << " reported " << seen[i] << " times";
    LaunchedPhoton p = launch_photon(s.seed, i, inc.theta_i, inc.phi_i, s.source.phi_i_uniform);
    const PhotonOutcome r = reference.trace(p.wi, p.h, p.rng, &reference_counters);
    ASSERT_EQ(batched_phi[i], p.phi_i);
    const PhotonOutcome& b = batched[i];
    const bool same = r.fate == b.fate && r.segments == b.segments &&
                      std::abs(r.path_length - b.path_length) <= 1e-7 * (1.0 + r.path_length) &&
                      (r.direction - b.direction).norm() <= drift(r.segments) &&
                      (r.fate == PhotonFate::Truncated ||
                       (std::abs(r.theta - b.theta) <= drift(r.segments) &&
                        std::abs(r.phi - b.phi) <= drift(r.segments))) &&
                      std::abs(r.weight - b.weight) <= drift(r.segments) &&
                      same_scored(r.scored, scored[i]);
    // Light-guided paths are chaotic: after ~50 segments the last-bit
    // drift grows beyond any fixed tolerance (judged apart, below).
    const bool long_path = r.segments > kLongPath;
    differ += !same && !long_path;
    long_paths += long_path;
    long_differ += !same && long_path;
    diverged_segments += std::abs(r.segments - b.segments);
  }
  std::printf("%s: %d of %llu photons differ; of %d paths longer than %d segments, %d\n", what,
              differ, static_cast<unsigned long long>(n), long_paths, kLongPath, long_differ);
  EXPECT_LE(differ, static_cast<int>(n / 1000)) << what;
  // Expected-value scoring follows many more photons along light-guided
  // paths (past their TT exit) than the analog estimator does.
  EXPECT_LE(long_differ, long_paths / 2) << what;
  // The same work, counted lane by lane in the batch. A photon whose path
  // came apart (a light-guided one, after ~100 segments of last-bit drift)
  // has its events and normals for a different number of segments: at most
  // a few events per segment (repeated events of the consistency rule) and
  // about 1.7 candidate normals per event, hence 4 per segment of difference.
  EXPECT_NEAR(counters.events, reference_counters.events,
              1e-3 * reference_counters.events + 4.0 * diverged_segments) << what;
  EXPECT_NEAR(counters.normal_draws, reference_counters.normal_draws,
              1e-3 * reference_counters.normal_draws + 4.0 * diverged_segments) << what;
  EXPECT_EQ(counters.sampler_caps, reference_counters.sampler_caps) << what;
}

// Both estimators (Settings::estimator): with expected-value scoring the
// exits scored on the way match too, one by one.
void expect_same_photons(Settings s, const char* what) {
  for (const Estimator e : {Estimator::Analog, Estimator::ExpectedValue}) {
    s.estimator = e;
    expect_same_photons_with(s, std::string(what) + ", " + to_string(e));
  }
}

TEST(BatchTracer, SmoothCircleMatchesReference) {
  expect_same_photons(testing::smooth_circle(37.0, 1), "smooth circle");
}

TEST(BatchTracer, RoughTiltedAbsorbingEllipseMatchesReference) {
  Settings s = testing::smooth_circle(17.0, 1);
  s.fiber.eccentricity = 0.8;
  s.fiber.sigma_a = {0.2, 0.4, 0.8};
  testing::make_rough(s, 7.5, 3.0);
  s.source.phi_i = {deg_to_rad(11.0)};
  expect_same_photons(s, "rough tilted ellipse");
  s.source.phi_i_uniform = true;
  s.roughness.beta_long = {deg_to_rad(25.0)};
  s.roughness.beta_azim = {deg_to_rad(4.0)};
  expect_same_photons(s, "rough ellipse, uniform phi_i, beta 25/4");
}

// Small beta on a tilted fiber at oblique incidence: the far-tail sampler
// (SPEC section 3), which the batch tracer runs lane by lane.
TEST(BatchTracer, FarTailNormalsMatchReference) {
  Settings s = testing::smooth_circle(60.0, 1);
  testing::make_rough(s, 0.5, 3.0);
  expect_same_photons(s, "beta 0.5, tilt 3, theta_i 60");
}

// Steep tilt: light-guided photons meet the tilted normal from behind at
// most events (case d, the slow one), so the far-tail sampler runs often.
TEST(BatchTracer, SteepTiltMatchesReference) {
  Settings s = testing::smooth_circle(30.0, 1);
  testing::make_rough(s, 5.0, 20.0);
  s.max_segments = 30;
  expect_same_photons(s, "tilt 20, beta 5, max_segments 30");
}

// Stokes light (SPEC section 3) runs batched too: the Stokes vector and its
// reference axis live in lanes; a photon's reflect/refract choices follow it.
TEST(BatchTracer, StokesLightMatchesReference) {
  Settings s = testing::smooth_circle(40.0, 1);
  s.polarization = Polarization::Stokes;
  expect_same_photons(s, "stokes, smooth circle");
  s.fiber.eccentricity = 0.8;
  testing::make_rough(s, 7.5, 3.0);
  s.source.phi_i = {deg_to_rad(11.0)};
  expect_same_photons(s, "stokes, rough tilted ellipse");
}

TEST(BatchTracer, ExitBlurMatchesReference) {
  Settings s = testing::smooth_circle(-41.0, 1);
  s.fiber.scale_tilt = deg_to_rad(-2.0);
  s.roughness.model = RoughnessModel::ExitBlur;
  s.roughness.beta_long = {deg_to_rad(5.0), deg_to_rad(10.0)};
  s.roughness.beta_azim = {deg_to_rad(8.0)};
  expect_same_photons(s, "exit blur");
}

TEST(BatchTracer, GuidedPhotonsAndSegmentLimitMatchReference) {
  Settings s = testing::smooth_circle(30.0, 1);
  testing::make_rough(s, 5.0, 3.0);
  s.max_segments = 20;  // many photons reach the limit
  expect_same_photons(s, "max_segments 20");
}

}  // namespace
}  // namespace fiberlab::sim
