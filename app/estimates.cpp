#include "app/estimates.h"

#include "common/error.h"

namespace fiberlab::app {

BinEstimates bin_estimates(const sim::ResultFile& r) {
  const std::size_t n = r.weight_sum.size();
  BinEstimates out;
  out.mean.resize(n);
  out.std_err.resize(n);
  out.density.resize(n);
  out.density_std_err.resize(n);
  const int nt = r.grid.n_theta(), np = r.grid.n_phi(), C = r.channels;
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t k = i / r.bin_cells();
    const sim::Estimate e = sim::bin_estimate(r.weight_sum[i], r.weight_sq_sum[i], r.photons[k]);
    const std::size_t b = i / C;  // (k, lobe, theta, phi)
    const double omega = r.grid.solid_angle(static_cast<int>(b / np % nt), static_cast<int>(b % np));
    out.mean[i] = e.mean;
    out.std_err[i] = e.std_error;
    out.density[i] = e.mean / omega;
    out.density_std_err[i] = e.std_error / omega;
  }
  return out;
}

Marginal marginal(const sim::ResultFile& r, const std::string& axis) {
  if (axis != "theta" && axis != "phi") throw Error("marginal axis '" + axis + "': must be theta or phi");
  const bool theta = axis == "theta";
  const std::size_t K = r.configs();
  const int L = r.lobes, nt = r.grid.n_theta(), np = r.grid.n_phi(), C = r.channels;
  const int n = theta ? nt : np;
  std::vector<double> s1(K * L * n * C, 0.0), s2(s1.size(), 0.0);
  for (std::size_t k = 0; k < K; ++k)
    for (int l = 0; l < L; ++l)
      for (int i = 0; i < nt; ++i)
        for (int j = 0; j < np; ++j)
          for (int c = 0; c < C; ++c) {
            const std::size_t from = r.cell(k, l, i, j, c);
            const std::size_t to = ((k * L + l) * n + (theta ? i : j)) * C + c;
            s1[to] += r.weight_sum[from];
            // Approximation under estimator expected_value: a photon that
            // leaves in several bins of one marginal cell adds cross terms
            // this sum of bins' S2 lacks (all >= 0), so the marginal's
            // standard error is then a lower bound (docs/PHYSICS.md
            // "Estimator"); exact for the analog estimator.
            s2[to] += r.weight_sq_sum[from];
          }
  Marginal out;
  out.n = n;
  out.mean.resize(s1.size());
  out.std_err.resize(s1.size());
  for (std::size_t x = 0; x < s1.size(); ++x) {
    const sim::Estimate e = sim::bin_estimate(s1[x], s2[x], r.photons[x / (static_cast<std::size_t>(L) * n * C)]);
    out.mean[x] = e.mean;
    out.std_err[x] = e.std_error;
  }
  return out;
}

}  // namespace fiberlab::app
