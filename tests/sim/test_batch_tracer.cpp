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
#include <utility>

#include "sim/life/batch_tracer.h"
#include "sim/life/source.h"
#include "tests/sim/batched_vs_reference.h"
#include "tests/sim/sim_test_support.h"

namespace fiberlab::sim {
namespace {

using testing::drift;
using testing::expect_same_photons_with;

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
  s.fiber.roughness = roughness::Gaussian{deg_to_rad(25.0), deg_to_rad(4.0)};
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
  s.fiber.roughness = roughness::ExitBlur{{{deg_to_rad(5.0), deg_to_rad(10.0)}, {deg_to_rad(8.0)}}};
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
  Medulla m;
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

// The microfacet models (sim/roughness/roughness_microfacet.h) run batched:
// ellipse, tilt, absorption, isotropic and anisotropic alpha, with and
// without Smith G1 masking (weights, Lost photons and each loss compared),
// scalar and Stokes light.
Settings microfacet_case(MicrofacetModel model, double ax, double ay, Masking masking) {
  Settings s = testing::smooth_circle(17.0, 1);
  s.fiber.eccentricity = 0.8;
  s.fiber.scale_tilt = deg_to_rad(3.0);
  s.fiber.sigma_a = {0.2, 0.4, 0.8};
  s.source.phi_i = {deg_to_rad(11.0)};
  s.fiber.roughness = testing::microfacet(model, ax, ay, masking);
  return s;
}

// GGX's sampler is one operation sequence for one photon and a vector
// (sincos_turn, square roots, divisions); as for the gaussian model, the
// compiler may fuse a product into a sum in one form and not the other, so
// paths agree to rounding, not always to the last bit (the count printed).
TEST(BatchTracer, GgxMatchesReference) {
  for (const Masking masking : {Masking::None, Masking::SmithG1}) {
    for (const auto& [ax, ay] : {std::pair{0.3, 0.3}, std::pair{0.15, 0.5}}) {
      const Settings s = microfacet_case(MicrofacetModel::GGX, ax, ay, masking);
      const std::string what = "ggx " + std::to_string(ax) + "/" + std::to_string(ay) +
                               (masking == Masking::SmithG1 ? " smith_g1" : "");
      expect_same_photons(s, what.c_str());
    }
  }
  // Photons launched one lane at a time (a random fiber rotation), each
  // given its list of losses there.
  Settings s = microfacet_case(MicrofacetModel::GGX, 0.3, 0.3, Masking::SmithG1);
  s.source.phi_i_uniform = true;
  expect_same_photons(s, "ggx 0.3 smith_g1, uniform phi_i");
}

// Beckmann's Newton iteration uses the C library's erfc and exp for one
// photon and xsimd's for a vector: normals may differ in the last bits.
TEST(BatchTracer, BeckmannMatchesReference) {
  for (const Masking masking : {Masking::None, Masking::SmithG1}) {
    for (const auto& [ax, ay] : {std::pair{0.3, 0.3}, std::pair{0.5, 0.15}}) {
      const Settings s = microfacet_case(MicrofacetModel::Beckmann, ax, ay, masking);
      const std::string what = "beckmann " + std::to_string(ax) + "/" + std::to_string(ay) +
                               (masking == Masking::SmithG1 ? " smith_g1" : "");
      expect_same_photons(s, what.c_str());
    }
  }
}

TEST(BatchTracer, MicrofacetStokesMatchesReference) {
  for (const MicrofacetModel model : {MicrofacetModel::GGX, MicrofacetModel::Beckmann}) {
    Settings s = microfacet_case(model, 0.2, 0.35, Masking::SmithG1);
    s.polarization = Polarization::Stokes;
    expect_same_photons(s, model == MicrofacetModel::GGX ? "stokes ggx" : "stokes beckmann");
  }
}

// Whether a model runs batched is its type's property (RunsBatched,
// sim/roughness/roughness_model.h): every registered model does; a model
// written for one photon only does not, and would go to the reference tracer.
struct OnePhotonOnly {
  life::FacetDraw<double> draw_normal(const life::Vec3Of<double>& d,
                                      const life::BoundaryFrame<double>&, bool live,
                                      life::LaneRandom<double>&, double&,
                                      life::LifeCounts<double>&, int) const {
    return {d, live, false};
  }
};
static_assert(!life::RunsBatched<OnePhotonOnly>);
static_assert(life::RunsBatched<life::GaussianRoughness>);
static_assert(life::RunsBatched<MicrofacetLifeModel>);

TEST(BatchTracer, EveryMicrofacetModelRunsBatched) {
  const double beta = deg_to_rad(5.0);
  for (const Roughness& model : {Roughness(roughness::Smooth{{{beta}, {beta}}}), Roughness(roughness::Gaussian{beta, beta}),
                                 Roughness(roughness::ExitBlur{{{beta}, {beta}}}),
                                 testing::microfacet(MicrofacetModel::GGX, 0.3, 0.3),
                                 testing::microfacet(MicrofacetModel::Beckmann, 0.3, 0.3)}) {
    Settings s = microfacet_case(MicrofacetModel::GGX, 0.3, 0.3, Masking::None);
    s.fiber.roughness = model;
    EXPECT_TRUE(runs_batched(make_roughness(s))) << roughness::name(model);
  }
}

}  // namespace
}  // namespace fiberlab::sim
