#pragma once
// Energy conservation over a theta_i sweep (d'Eon et al. 2011, Figs. 3 and 5):
// per-lobe and total energy from the simulation's ledger and from each model
// integrated over the sphere (the sum of its bin probabilities over a grid;
// every model's bin_probabilities() integrates its density within each bin,
// so the sum is the integral over the sphere to the model's quadrature
// accuracy, whatever the grid).
#include <string>
#include <vector>

#include "analytic/model.h"
#include "compare/models.h"
#include "sim/store/result_file.h"

namespace fiberlab::compare {

struct EnergyCurve {
  std::string label;       // "simulation" or the model spec (and its beta)
  bool simulated = false;
  double beta_long = -1.0; // radians when swept (--beta-sweep), else < 0
  int lobes = 0, channels = 0;
  std::vector<double> theta_i;          // K, radians
  std::vector<double> lobe, lobe_error; // K x L x C (errors: simulation only, else 0)
  std::vector<double> absorbed, truncated, lost, ledger;  // K x C (simulation only)
  std::vector<double> roulette;  // K x C (simulation only; signed, 0 but with expected_value)

  double at(std::size_t k, int l, int c) const { return lobe[(k * lobes + l) * channels + c]; }
  double error(std::size_t k, int l, int c) const { return lobe_error[(k * lobes + l) * channels + c]; }
  double total(std::size_t k, int c) const;        // sum over lobes
  double total_error(std::size_t k, int c) const;  // lobes' errors in quadrature (upper bound)
  double three_lobe(std::size_t k, int c) const;   // R + TT + TRT
};

// The simulation's ledger: exited per lobe / N (with the standard errors of
// sim::lobe_energy), absorbed / N, truncated / N, lost / N (masking), and the
// Russian roulette's signed term / N (expected-value scoring), and the
// ledger sum (exited + absorbed + truncated + lost - roulette) / N, which is
// 1 to rounding.
EnergyCurve simulation_energy(const sim::ResultFile& result);

// A model's curve against a fiber with a medulla (docs/FUR.md): the models
// have none, so they predict nothing in its last lobe, `scattered`; the
// curve gains that lobe with energy 0.
void add_scattered_lobe(EnergyCurve& model_curve);

// One model over theta_i (phi_i = 0), integrated on an n_theta x n_phi grid.
EnergyCurve model_energy(const analytic::Model& model, const std::string& label,
                         const std::vector<double>& theta_i, int n_theta, int n_phi);

}  // namespace fiberlab::compare
