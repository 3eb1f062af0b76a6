// The batched, vectorised tracer against the reference tracer, photon by
// photon: each photon draws from its own stream in the same order in both,
// so paths agree to rounding (1e-7 allows the drift of light-guided photons
// over a hundred segments), except where the two round differently in the
// last bit and that flips a random decision (rare: the sampler's sin, cos
// and log are one code for both, sim/simd/life_trig.h and sim/simd/life_log.h, but the
// compiler may fuse a product into a sum in one form and not the other).
#include <gtest/gtest.h>

#include <cstdio>
#include <map>

#include "sim/life/batch_tracer.h"
#include "sim/life/source.h"
#include "tests/sim/sim_test_support.h"

namespace fiberlab::sim {
namespace {

void expect_same_photons(const Settings& s, const char* what) {
  const std::uint64_t n = 50000;
  const Tracer reference(s);
  const BatchTracer batch(s);
  const auto inc = s.incidences().front();
  std::vector<PhotonOutcome> batched(n);
  std::vector<double> batched_phi(n);
  std::vector<int> seen(n, 0);
  TracerCounters counters;
  batch.trace(inc.theta_i, inc.phi_i, 0, n,
              [&](const FinishedPhotons& f) {
                for (int j = 0; j < f.n; ++j) {
                  const std::uint64_t i = f.photon[j];
                  batched[i] = f.outcome(j);
                  batched_phi[i] = f.phi_i[j];
                  ++seen[i];
                }
              },
              counters);
  int differ = 0;
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
                      (r.direction - b.direction).norm() <= 1e-7 &&
                      r.scattered == b.scattered &&
                      std::abs(r.medulla_path - b.medulla_path) <= 1e-7 * (1.0 + r.medulla_path) &&
                      (r.fate == PhotonFate::Truncated ||
                       (std::abs(r.theta - b.theta) <= 1e-7 && std::abs(r.phi - b.phi) <= 1e-7));
    differ += !same;
    diverged_segments += std::abs(r.segments - b.segments);
  }
  std::printf("%s: %d of %llu photons differ\n", what, differ, static_cast<unsigned long long>(n));
  EXPECT_LE(differ, static_cast<int>(n / 1000)) << what;
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

// A scattering medulla (sim/life/medulla.h) with a Fresnel boundary, in
// scalar and Stokes light: the walk's masks draw what the scalar walk draws.
// Scattering sends about 2% of the photons along the fiber, light-guided
// for hundreds of segments, where last-bit drift parts the two paths (as
// for the guided photons above): max_segments 30 ends them alike.
TEST(BatchTracer, MedullaMatchesReference) {
  Settings s = testing::smooth_circle(23.0, 1);
  s.fiber.eccentricity = 0.8;
  s.fiber.sigma_a = {0.2, 0.4};
  testing::make_rough(s, 5.0, 3.0);
  MedullaSettings m;
  m.radius = 0.55;
  m.sigma_s = 3.0;
  m.sigma_a = {0.1, 0.3};
  m.g = 0.6;
  m.eta = 1.3;
  s.fiber.medulla = m;
  s.max_segments = 30;
  expect_same_photons(s, "medulla, scalar");
  s.polarization = Polarization::Stokes;
  expect_same_photons(s, "medulla, stokes");
}

}  // namespace
}  // namespace fiberlab::sim
