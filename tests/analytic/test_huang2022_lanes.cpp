// huang2022's SIMD paths (analytic/huang2022_lanes.h) in double against its
// scalar paths (huang2022.cpp's Paths, the ones density() uses): the same
// point set through both must give the same lobe energies, losses and bins up to
// rounding, in every mode of the model (roughness 0 and > 0, each masking,
// both fluxes, both residuals, tilt, ellipse, absorbing channels, 2 to 4
// lobes, a point count that is not a multiple of the lane width,
// mirror-averaged and not).
// A peer test: the scalar paths are held to the physics oracles in
// test_huang2022.cpp, these to the scalar paths.
// Mutations caught: the correlated masking's (1 + L_i) dropped in the lanes
// (energies off by 1e-2); interface 1's chord transmittance not kept for the
// residual; the residual's A_avg = A_1 A_2 without the square root; the last
// lane group's padding points given weight.
#include <gtest/gtest.h>

#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "analytic/huang2022.h"
#include "analytic/huang2022_lanes.h"
#include "common/bin_grid.h"
#include "common/units.h"

using namespace fiberlab;
using namespace fiberlab::analytic;

namespace {

struct Case {
  std::string name;
  Huang2022Params p;
  double theta_deg, phi_deg;
};

std::vector<Case> cases() {
  std::vector<Case> out;
  auto base = [] {
    Huang2022Params p;
    p.sigma_a = {0.0};
    p.quadrature_points = 20003;  // not a multiple of 8 lanes
    return p;
  };
  Huang2022Params p = base();
  p.roughness = 0.3;
  out.push_back({"ggx 0.3 separable", p, 40.0, 0.0});
  p.masking = HuangMasking::Correlated;
  p.tilt = deg_to_rad(3.0);
  out.push_back({"ggx 0.3 correlated tilt 3", p, 60.0, 0.0});
  p.masking = HuangMasking::None;
  p.eccentricity = 0.85;
  p.sigma_a = {0.2, 0.6, 1.3};
  out.push_back({"ggx 0.3 no masking, ellipse, absorbing", p, 25.0, 30.0});
  p = base();
  p.roughness = 0.1;
  p.tilt = deg_to_rad(-5.0);
  p.mesonormal_flux = false;
  p.eccentricity = 0.7;
  p.lobes = 2;  // R, then every p >= 1 in one lobe
  out.push_back({"ggx 0.1 macro flux ellipse, 2 lobes", p, 75.0, 90.0});
  p = base();
  p.roughness = 0.0;
  p.sigma_a = {0.5};
  p.lobes = 3;
  out.push_back({"smooth absorbing (sampled residual spread), 3 lobes", p, 30.0, 0.0});
  p = base();
  p.roughness = 0.2;
  p.residual = HuangResidual::CyclesEval;
  p.masking = HuangMasking::Correlated;
  p.sigma_a = {0.0, 0.8};
  p.tilt = deg_to_rad(4.0);
  out.push_back({"cycles_eval residual", p, 50.0, 10.0});
  p.lobe_scale = {1.0, 1.0, 0.0};
  out.push_back({"cycles_eval residual, TRT factor 0", p, 50.0, 10.0});
  p = base();
  p.roughness = 0.3;
  p.form = HuangForm::CyclesEval;
  p.masking = HuangMasking::Correlated;
  p.residual = HuangResidual::CyclesEval;
  p.tilt = deg_to_rad(8.0);
  p.eccentricity = 0.8;
  p.sigma_a = {0.3};
  out.push_back({"form cycles_eval, tilt 8, ellipse", p, 60.0, 20.0});
  return out;
}

void expect_close(const std::vector<double>& a, const std::vector<double>& b, double tol, const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (std::size_t k = 0; k < a.size(); ++k) EXPECT_NEAR(a[k], b[k], tol) << what << " [" << k << "]";
}

}  // namespace

// The energies: sums over the same points in another order (rounding only).
TEST(Huang2022, LanesEqualTheScalarPathsInEnergy) {
  for (const Case& k : cases()) {
    Huang2022 lanes(k.p), scalar(k.p);
    lanes.set_paths(HuangPaths::DoubleLanes);
    scalar.set_paths(HuangPaths::Scalar);
    const double ti = deg_to_rad(k.theta_deg), pi = deg_to_rad(k.phi_deg);
    const HuangEnergies a = lanes.energies(ti, pi), b = scalar.energies(ti, pi);
    expect_close(a.lobe, b.lobe, 1e-12, k.name + " lobe");
    expect_close(a.masked, b.masked, 1e-12, k.name + " masked");
    expect_close(a.stopped, b.stopped, 1e-12, k.name + " stopped");
    EXPECT_NEAR(a.incident, b.incident, 1e-12) << k.name;
    EXPECT_GT(a.lobe[0], 1e-3) << k.name;  // the case has light to compare
  }
}

// The bins: every exit in the same bin (its angles by xsimd's asin and atan2
// instead of the C library's: an exit within rounding of a bin edge could
// change bins, none does here).
TEST(Huang2022, LanesEqualTheScalarPathsInBins) {
  for (const BinGrid& g :
       {BinGrid::make(24, 36, ThetaBinning::Uniform), BinGrid::make(17, 35, ThetaBinning::EqualArea)})
    for (const Case& k : cases()) {
      Huang2022 lanes(k.p), scalar(k.p);
      lanes.set_paths(HuangPaths::DoubleLanes);
      scalar.set_paths(HuangPaths::Scalar);
      const double ti = deg_to_rad(k.theta_deg), pi = deg_to_rad(k.phi_deg);
      expect_close(lanes.bin_probabilities(g, ti, pi), scalar.bin_probabilities(g, ti, pi), 1e-13,
                   k.name + " " + std::to_string(g.n_theta()));
    }
}

// The quadrature's points run in a fixed number of blocks summed in block
// order: 1, 2 or 3 threads give the same bits (the atlas's bit-identity
// across threads, ranks and resumes rests on it), at the cases' fixed points
// and at quadrature_points=auto (its pilot, its choice and its points).
// Mutation caught: the blocks summed as their threads finish (a per-thread
// accumulator).
TEST(Huang2022, BinsAndEnergiesAreTheSameOnAnyNumberOfThreads) {
  const int threads = omp_get_max_threads();
  const BinGrid g = BinGrid::make(18, 36, ThetaBinning::Uniform);
  std::vector<Case> all = cases();
  Case automatic = all.front();
  automatic.name += " (auto, 30k photons)";
  automatic.p.quadrature_points = kAutoQuadraturePoints;
  automatic.p.quadrature_photons = 30000.0;  // a few pilots' worth of points
  all.push_back(automatic);
  for (const Case& k : all) {
    const Huang2022 model(k.p);
    const double ti = deg_to_rad(k.theta_deg), pi = deg_to_rad(k.phi_deg);
    omp_set_num_threads(1);
    const std::vector<double> bins1 = model.bin_probabilities(g, ti, pi);
    const HuangEnergies e1 = model.energies(ti, pi);
    for (int n : {2, 3}) {
      omp_set_num_threads(n);
      EXPECT_EQ(model.bin_probabilities(g, ti, pi), bins1) << k.name << ", " << n << " threads";
      const HuangEnergies en = model.energies(ti, pi);
      EXPECT_EQ(en.lobe, e1.lobe) << k.name << ", " << n << " threads";
      EXPECT_EQ(en.masked, e1.masked) << k.name;
      EXPECT_EQ(en.stopped, e1.stopped) << k.name;
      EXPECT_EQ(en.incident, e1.incident) << k.name;
    }
  }
  omp_set_num_threads(threads);
}

// The float lanes (the quadrature's) against the double lanes on the same
// points. Float arithmetic rounds each path's weight and exit direction by
// a few 1e-7 relative; the quadrature's own error is ~1e-3 of a lobe at
// 2^18 points and 0.1 standard error of the atlas's bins at its default
// (analytic/huang2022.h). Per lobe and channel the energies must agree to
// 1e-5 relative (measured up to 3.1e-6: cycles_eval's residual, whose
// 1 - R2 cancels in float as R2 -> 1) and the bins to 1e-4 of the lobe's
// energy in L1 (measured up to 1.7e-5: exits within float rounding of a bin
// edge, ~1e-7 rad, land in the neighbouring bin). The theta grid has 25 bins
// so that no case's specular cone theta_r = -theta_i is a bin edge (a
// smooth fiber puts its whole R lobe on that cone, where rounding alone
// decides the bin, in double as in float). Mutation caught: the residual's
// denominator as 1 - A (1 - T) in the float lanes (1.1e-3 on white fibers).
TEST(Huang2022, FloatLanesAreTheDoubleLanesToRounding) {
  const BinGrid g = BinGrid::make(25, 36, ThetaBinning::Uniform);
  for (Case k : cases()) {
    k.p.quadrature_points = 1 << 18;
    Huang2022 f(k.p), d(k.p);
    d.set_paths(HuangPaths::DoubleLanes);
    const double ti = deg_to_rad(k.theta_deg), pi = deg_to_rad(k.phi_deg);
    const HuangEnergies ef = f.energies(ti, pi), ed = d.energies(ti, pi);
    const std::vector<double> bf = f.bin_probabilities(g, ti, pi), bd = d.bin_probabilities(g, ti, pi);
    const int C = static_cast<int>(k.p.sigma_a.size()), L = k.p.lobes;
    const std::size_t per_lobe = static_cast<std::size_t>(g.n_theta()) * g.n_phi() * C;
    for (int l = 0; l < L; ++l)
      for (int c = 0; c < C; ++c) {
        const double x = ed.lobe[l * C + c];
        if (x < 1e-6) continue;
        double l1 = 0.0;
        for (std::size_t b = l * per_lobe + c; b < (l + 1) * per_lobe; b += C) l1 += std::abs(bf[b] - bd[b]);
        std::printf("%s, lobe %d channel %d: energy %.2g, bins (L1) %.2g relative\n", k.name.c_str(), l, c,
                    std::abs(ef.lobe[l * C + c] - x) / x, l1 / x);
        EXPECT_NEAR(ef.lobe[l * C + c], x, 1e-5 * x) << k.name << " lobe " << l << " channel " << c;
        EXPECT_LT(l1, 1e-4 * x) << k.name << " lobe " << l << " channel " << c;
      }
    for (int c = 0; c < C; ++c) {
      EXPECT_NEAR(ef.masked[c], ed.masked[c], 1e-6) << k.name;
      EXPECT_NEAR(ef.stopped[c], ed.stopped[c], 1e-6) << k.name;
    }
  }
}

// TracerT::trace told to follow some orders only (quadrature_points=auto
// traces the points beyond what a lobe needs so, huang2022.cpp): the orders
// it follows have the exits, weights and residual of a path that follows
// every order, to the bit, with the ledger kept or not; the others have
// none. On every case (the cycles_eval residual arrives at interface 2, on
// the way to TRT), in float and double lanes, for random points.
// Mutations caught: the order gate of interface 2 or 3 dropped (TT or TRT
// exits where they were not asked for); cycles_eval's residual at interface
// 2 kept without its order; the ledger bit read as an order.
template <class Tracer>
void expect_only_the_followed_orders(const Case& k, const typename Tracer::Exits& all,
                                     const typename Tracer::Exits& some, unsigned orders) {
  using B = typename Tracer::Batch;
  using T = typename B::value_type;
  constexpr int W = Tracer::kWidth;
  const int C = static_cast<int>(k.p.sigma_a.size());
  auto lanes_of = [](const B& x) {
    std::array<T, W> a;
    x.store_unaligned(a.data());
    return a;
  };
  auto live_of = [&](const typename B::batch_bool_type& m) { return lanes_of(xsimd::select(m, B(1), B(0))); };
  const std::string what = k.name + " orders " + std::to_string(orders);
  for (int p = 0; p < 3; ++p) {
    const bool followed = orders >> p & 1u;
    const auto live = live_of(some.live[p]), live_all = live_of(all.live[p]);
    const auto x = lanes_of(some.dir[p].x), x_all = lanes_of(all.dir[p].x);
    for (int l = 0; l < W; ++l) {
      ASSERT_EQ(live[l], followed ? live_all[l] : T(0)) << what << " p " << p;
      if (live[l] != T(0)) {
        ASSERT_EQ(x[l], x_all[l]) << what << " p " << p;
      }
    }
    for (int c = 0; c < C; ++c) {
      const auto w = lanes_of(some.w[p][c]), w_all = lanes_of(all.w[p][c]);
      for (int l = 0; l < W; ++l) ASSERT_EQ(w[l], followed ? w_all[l] : T(0)) << what << " p " << p;
    }
  }
  for (int c = 0; c < C; ++c) {
    const auto r = lanes_of(some.residual[c]), r_all = lanes_of(all.residual[c]);
    for (int l = 0; l < W; ++l) ASSERT_EQ(r[l], orders & 8u ? r_all[l] : T(0)) << what << " residual";
  }
}

template <class Tracer>
void expect_orders_apart(const Case& k) {
  using B = typename Tracer::Batch;
  using T = typename B::value_type;
  constexpr int W = Tracer::kWidth;
  const Tracer tracer(k.p, deg_to_rad(k.theta_deg), deg_to_rad(k.phi_deg));
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (int group = 0; group < 200; ++group) {
    B u[huang_lanes::kDims];
    for (B& x : u) {
      alignas(64) T a[W];
      for (T& v : a) v = static_cast<T>(uniform(rng));
      x = B::load_aligned(a);
    }
    typename Tracer::Exits all, some;
    tracer.trace(u, B(1.0), all);
    for (unsigned exits : {0b0001u, 0b0010u, 0b0100u, 0b1000u, 0b0110u, 0b1100u, 0b0011u, 0b1111u})
      for (unsigned ledger : {0u, huang_lanes::kLedger}) {
        tracer.trace(u, B(1.0), some, exits | ledger);
        expect_only_the_followed_orders<Tracer>(k, all, some, exits | ledger);
        if (::testing::Test::HasFatalFailure()) return;
      }
  }
}

TEST(Huang2022, TracingSomeOrdersLeavesTheirExitsAsTheyAre) {
  for (const Case& k : cases()) {
    expect_orders_apart<huang_lanes::FloatTracer>(k);
    expect_orders_apart<huang_lanes::DoubleTracer>(k);
  }
}
