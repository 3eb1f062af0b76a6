#include "analytic/model.h"

#include <cmath>

#include "analytic/quadrature.h"

namespace fiberlab::analytic {

std::vector<double> Model::bin_probabilities(const BinGrid& grid, double theta_i,
                                             double phi_i) const {
  constexpr int kOrder = 6;
  const GaussLegendre& gl = gauss_legendre(kOrder);
  const int nt = grid.n_theta(), np = grid.n_phi(), L = lobes();
  std::vector<double> value;
  density(0, theta_i, phi_i, 0.0, 0.0, value);
  const std::size_t C = value.size();
  std::vector<double> out(static_cast<std::size_t>(L) * nt * np * C, 0.0);
  for (int lobe = 0; lobe < L; ++lobe) {
    for (int i = 0; i < nt; ++i) {
      const double t0 = grid.theta_edges[i], t1 = grid.theta_edges[i + 1];
      for (int j = 0; j < np; ++j) {
        const double f0 = grid.phi_edges[j], f1 = grid.phi_edges[j + 1];
        double* bin = &out[((static_cast<std::size_t>(lobe) * nt + i) * np + j) * C];
        for (int a = 0; a < kOrder; ++a) {
          const double tr = 0.5 * (t0 + t1) + 0.5 * (t1 - t0) * gl.x[a];
          const double wt = 0.5 * (t1 - t0) * gl.w[a];
          for (int b = 0; b < kOrder; ++b) {
            const double ph = 0.5 * (f0 + f1) + 0.5 * (f1 - f0) * gl.x[b];
            const double w = wt * 0.5 * (f1 - f0) * gl.w[b];
            density(lobe, theta_i, phi_i, tr, ph, value);
            for (std::size_t c = 0; c < C; ++c) bin[c] += w * value[c];
          }
        }
      }
    }
  }
  return out;
}

}  // namespace fiberlab::analytic
