#include "compare/energy.h"

#include <algorithm>
#include <cmath>

#include "common/error.h"

namespace fiberlab::compare {

double EnergyCurve::total(std::size_t k, int c) const {
  double s = 0.0;
  for (int l = 0; l < lobes; ++l) s += at(k, l, c);
  return s;
}

double EnergyCurve::total_error(std::size_t k, int c) const {
  double s = 0.0;
  for (int l = 0; l < lobes; ++l) s += error(k, l, c) * error(k, l, c);
  return std::sqrt(s);
}

double EnergyCurve::three_lobe(std::size_t k, int c) const {
  double s = 0.0;
  for (int l = 0; l < std::min(lobes, 3); ++l) s += at(k, l, c);
  return s;
}

void add_scattered_lobe(EnergyCurve& e) {
  const std::size_t K = e.theta_i.size(), L = static_cast<std::size_t>(e.lobes), C = static_cast<std::size_t>(e.channels);
  std::vector<double> lobe(K * (L + 1) * C, 0.0), error(K * (L + 1) * C, 0.0);
  for (std::size_t k = 0; k < K; ++k)
    for (std::size_t l = 0; l < L; ++l)
      for (std::size_t c = 0; c < C; ++c) {
        lobe[(k * (L + 1) + l) * C + c] = e.lobe[(k * L + l) * C + c];
        error[(k * (L + 1) + l) * C + c] = e.lobe_error[(k * L + l) * C + c];
      }
  e.lobe = std::move(lobe);
  e.lobe_error = std::move(error);
  ++e.lobes;
}

EnergyCurve simulation_energy(const sim::ResultFile& r) {
  EnergyCurve e;
  e.label = "simulation";
  e.simulated = true;
  e.lobes = r.lobes;
  e.channels = r.channels;
  e.theta_i = r.theta_i;
  const std::size_t K = r.configs();
  const int L = r.lobes, C = r.channels;
  e.lobe.assign(K * L * C, 0.0);
  e.lobe_error.assign(K * L * C, 0.0);
  e.absorbed.assign(K * C, 0.0);
  e.truncated.assign(K * C, 0.0);
  e.lost.assign(K * C, 0.0);
  e.roulette.assign(K * C, 0.0);
  e.ledger.assign(K * C, 0.0);
  for (std::size_t k = 0; k < K; ++k) {
    const double n = static_cast<double>(r.photons[k]);
    for (int c = 0; c < C; ++c) {
      double exited = 0.0;
      for (int l = 0; l < L; ++l) {
        // The ledger's exited weight is the lobe energy; its standard error
        // comes from the bins' S2 (sim::lobe_energy).
        const std::size_t i = (k * L + l) * C + c;
        const sim::Estimate est = sim::lobe_energy(r, k, l, c);
        e.lobe[i] = r.exited[i] / n;
        e.lobe_error[i] = est.std_error;
        exited += r.exited[i];
      }
      e.absorbed[k * C + c] = r.absorbed[k * C + c] / n;
      e.truncated[k * C + c] = r.truncated[k * C + c] / n;
      e.lost[k * C + c] = r.lost[k * C + c] / n;
      // (a ResultFile assembled without the term has none: 0)
      e.roulette[k * C + c] = r.roulette.empty() ? 0.0 : r.roulette[k * C + c] / n;
      e.ledger[k * C + c] = (exited + r.absorbed[k * C + c] + r.truncated[k * C + c] +
                             r.lost[k * C + c]) / n - e.roulette[k * C + c];
    }
  }
  return e;
}

EnergyCurve model_energy(const analytic::Model& model, const std::string& label,
                         const std::vector<double>& theta_i, int n_theta, int n_phi) {
  EnergyCurve e;
  e.label = label;
  e.lobes = model.lobes();
  e.theta_i = theta_i;
  const BinGrid grid = BinGrid::make(n_theta, n_phi, ThetaBinning::Uniform);
  const long K = static_cast<long>(theta_i.size());
  std::vector<std::vector<double>> bins(K);
  std::string error;
#pragma omp parallel for schedule(dynamic)
  for (long k = 0; k < K; ++k) {
    try {
      bins[k] = model.bin_probabilities(grid, theta_i[k], 0.0);
    } catch (const std::exception& ex) {
#pragma omp critical
      error = ex.what();
    }
  }
  if (!error.empty()) throw Error(error);
  const std::size_t per_lobe = static_cast<std::size_t>(n_theta) * n_phi;
  e.channels = K > 0 ? static_cast<int>(bins[0].size() / (per_lobe * e.lobes)) : 0;
  const int L = e.lobes, C = e.channels;
  e.lobe.assign(K * L * C, 0.0);
  e.lobe_error.assign(K * L * C, 0.0);
  for (long k = 0; k < K; ++k)
    for (int l = 0; l < L; ++l)
      for (std::size_t b = 0; b < per_lobe; ++b)
        for (int c = 0; c < C; ++c)
          e.lobe[(k * L + l) * C + c] += bins[k][(l * per_lobe + b) * C + c];
  return e;
}

}  // namespace fiberlab::compare
