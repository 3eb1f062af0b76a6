#pragma once
// Helpers shared by the simulator tests: build Settings in code and run them.
#include <cmath>
#include <vector>

#include "common/units.h"
#include "sim/store/result_file.h"
#include "sim/run/settings.h"
#include "sim/run/simulation.h"
#include "sim/roughness/microfacet_distribution.h"

namespace fiberlab::sim {

inline std::string to_string(MicrofacetModel m) {
  return m == MicrofacetModel::Beckmann ? "beckmann" : "ggx";
}

}  // namespace fiberlab::sim

namespace fiberlab::sim::testing {

// A smooth, untilted, circular, white fiber at one incident direction.
inline Settings smooth_circle(double theta_i_deg, std::uint64_t photons) {
  Settings s;
  s.photons = photons;
  s.seed = 12345;
  s.fiber.eta = 1.55;
  s.fiber.sigma_a = {0.0};
  s.fiber.roughness = roughness::Smooth{};
  s.source.theta_i = {deg_to_rad(theta_i_deg)};
  s.source.phi_i = {0.0};
  s.tally.n_theta = 90;
  s.tally.n_phi = 180;
  s.tally.lobes = 4;
  return s;
}

// Gaussian roughness of `beta_deg` (longitudinal and azimuthal) and a cuticle
// tilt of `tilt_deg`.
inline void make_rough(Settings& s, double beta_deg, double tilt_deg = 0.0) {
  s.fiber.scale_tilt = deg_to_rad(tilt_deg);
  s.fiber.roughness = roughness::Gaussian{deg_to_rad(beta_deg), deg_to_rad(beta_deg)};
}

// The microfacet roughness `model` with alpha per axis (common/roughness/microfacet.h).
inline Roughness microfacet(MicrofacetModel model, double alpha_long, double alpha_azim,
                            Masking masking = Masking::None) {
  const roughness::MicrofacetAlpha a{alpha_long, alpha_azim, masking};
  if (model == MicrofacetModel::Beckmann) return roughness::Beckmann{a};
  return roughness::Ggx{a};
}

// A roughness of `s` known to be of type Model.
template <class Model>
Model& roughness_of(Settings& s) {
  return std::get<Model>(s.fiber.roughness);
}

inline ResultFile run(const Settings& s, int threads = 2) {
  Simulation sim(s);
  return make_result(s, sim.grid(), sim.run(threads));
}

// Sum of S1 (and S2) over theta bins: the phi histogram of one lobe/channel.
inline std::vector<double> phi_marginal(const ResultFile& r, std::size_t k, int lobe, int c,
                                        std::vector<double>* s2 = nullptr) {
  std::vector<double> s1(r.grid.n_phi(), 0.0);
  if (s2) s2->assign(r.grid.n_phi(), 0.0);
  for (int i = 0; i < r.grid.n_theta(); ++i)
    for (int j = 0; j < r.grid.n_phi(); ++j) {
      s1[j] += r.weight_sum[r.cell(k, lobe, i, j, c)];
      if (s2) (*s2)[j] += r.weight_sq_sum[r.cell(k, lobe, i, j, c)];
    }
  return s1;
}

inline std::vector<double> theta_marginal(const ResultFile& r, std::size_t k, int lobe, int c,
                                          std::vector<double>* s2 = nullptr) {
  std::vector<double> s1(r.grid.n_theta(), 0.0);
  if (s2) s2->assign(r.grid.n_theta(), 0.0);
  for (int i = 0; i < r.grid.n_theta(); ++i)
    for (int j = 0; j < r.grid.n_phi(); ++j) {
      s1[i] += r.weight_sum[r.cell(k, lobe, i, j, c)];
      if (s2) (*s2)[i] += r.weight_sq_sum[r.cell(k, lobe, i, j, c)];
    }
  return s1;
}

// A chi-square over n bins has mean n and standard deviation sqrt(2n)
// (SPEC section 10): accept up to five standard deviations above the mean.
// With fixed seeds the outcome is deterministic; a correct simulator fails
// this with probability well below 1e-5 for the n used here.
inline double chi2_threshold(int dof) { return dof + 5.0 * std::sqrt(2.0 * dof); }

}  // namespace fiberlab::sim::testing
