#include "compare/comparison.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

#include "analytic/model.h"
#include "common/error.h"
#include "common/file_schema.h"

namespace fiberlab::compare {

void check_options(const Options& o, std::optional<double> max_chi2, OptionSpelling spelling) {
  auto check = [spelling](double x, const char* snake, const char* flag, bool ok, const char* allowed) {
    if (std::isfinite(x) && ok) return;
    throw Error(fmt::format("{} = {} is out of range (must be {})",
                            spelling == OptionSpelling::Python ? snake : flag, x, allowed));
  };
  check(o.min_effective, "min_effective", "--min-effective", o.min_effective > 0.0, "a number > 0");
  check(o.model_rel_error, "model_error", "--model-error",
        o.model_rel_error >= 0.0 && o.model_rel_error <= 1.0, "a relative error in [0, 1]");
  check(o.min_lobe_energy, "min_energy", "--min-energy",
        o.min_lobe_energy >= 0.0 && o.min_lobe_energy < 1.0,
        "in [0, 1): a fraction of the incident power; 1 or more would judge no lobe");
  if (max_chi2) check(*max_chi2, "max_chi2", "--max-chi2", *max_chi2 > 0.0, "a number > 0");
}

namespace {

// One histogram cell (a bin, a marginal bin or the pooled rest) in the
// currency of the comparison: sums of weights and squared weights, and the
// model's probability.
struct Cell {
  double s1 = 0.0, s2 = 0.0, m = 0.0;
  void add(const Cell& o) { s1 += o.s1; s2 += o.s2; m += o.m; }
  double effective() const { return s2 > 0.0 ? s1 * s1 / s2 : 0.0; }
};

// Variance of P = S1/N (SPEC s6) plus the model's quadrature error. For a
// cell the simulation barely reached (the rest cell) the simulation's own
// variance is unreliable, so it is floored by the Poisson variance the model
// implies, M r / N, r = mean weight of the lobe's photons (S2/S1 of the lobe).
double cell_variance(const Cell& c, double n, double weight_ratio, double q, bool floor) {
  const double p = c.s1 / n;
  double var = std::max(0.0, (c.s2 / n - p * p) / (n - 1.0));
  if (floor) var = std::max(var, c.m * weight_ratio / n);
  return var + (q * c.m) * (q * c.m);
}

// chi-square of cells: those with effective samples >= min compared
// one by one; the others pooled into one rest cell (when either side has mass).
ChiSquare chi_square(const std::vector<Cell>& cells, double n, double ratio, const Options& o,
                     std::vector<double>* residuals = nullptr, Cell* rest_out = nullptr) {
  ChiSquare x;
  Cell rest;
  for (const Cell& c : cells) {
    if (c.effective() >= o.min_effective) {
      const double r = (c.s1 / n - c.m) / std::sqrt(cell_variance(c, n, ratio, o.model_rel_error, false));
      x.chi2 += r * r;
      ++x.dof;
      if (residuals) residuals->push_back(r);
    } else {
      rest.add(c);
    }
  }
  if (rest.s1 > 0.0 || rest.m > 0.0) {
    const double var = cell_variance(rest, n, ratio, o.model_rel_error, true);
    if (var > 0.0) {
      const double r = (rest.s1 / n - rest.m) / std::sqrt(var);
      x.chi2 += r * r;
      ++x.dof;
      if (residuals) residuals->push_back(r);
    }
  }
  if (rest_out) *rest_out = rest;
  return x;
}

double bin_centre(const std::vector<double>& edges, int i) { return 0.5 * (edges[i] + edges[i + 1]); }

}  // namespace

std::vector<LobeComparison> compare(const sim::ResultFile& r,
                                    const std::vector<std::vector<double>>& model_bins,
                                    const std::vector<double>& alpha, const Options& o) {
  std::vector<LobeComparison> out;
  const int nt = r.grid.n_theta(), np = r.grid.n_phi(), C = r.channels;
  for (std::size_t k = 0; k < r.configs(); ++k) {
    const double n = static_cast<double>(r.photons[k]);
    const std::vector<double>& mb = model_bins.at(k);
    const std::size_t base = k * r.bin_cells();
    for (int lobe = 0; lobe < r.lobes; ++lobe) {
      for (int c = 0; c < C; ++c) {
        LobeComparison lc;
        lc.k = k;
        lc.lobe = lobe;
        lc.channel = c;
        lc.theta_i = r.theta_i[k];
        lc.phi_i = r.phi_i[k];
        std::vector<Cell> cells(static_cast<std::size_t>(nt) * np), th(nt), ph(np);
        Cell total;
        for (int i = 0; i < nt; ++i)
          for (int j = 0; j < np; ++j) {
            const std::size_t idx = r.cell(k, lobe, i, j, c);
            Cell cell{r.weight_sum[idx], r.weight_sq_sum[idx], mb[idx - base]};
            cells[static_cast<std::size_t>(i) * np + j] = cell;
            th[i].add(cell);
            ph[j].add(cell);
            total.add(cell);
          }
        const sim::Estimate e = sim::lobe_energy(r, k, lobe, c);
        lc.sim_energy = e.mean;
        lc.sim_error = e.std_error;
        lc.model_energy = total.m;
        lc.energy_z = e.std_error > 0 ? (total.m - e.mean) / e.std_error : 0.0;
        const double ratio = total.s1 > 0.0 ? total.s2 / total.s1 : 1.0;
        Cell rest;
        lc.bins = chi_square(cells, n, ratio, o, nullptr, &rest);
        lc.rest_sim = rest.s1 / n;
        lc.rest_model = rest.m;
        lc.compared_bins = lc.bins.dof - ((rest.s1 > 0.0 || rest.m > 0.0) ? 1 : 0);
        lc.theta_marginal = chi_square(th, n, ratio, o);
        lc.phi_marginal = chi_square(ph, n, ratio, o);
        const double es = total.s1 / n, em = total.m;
        for (const Cell& cell : cells) {
          const double a = es > 0 ? cell.s1 / n / es : 0.0, b = em > 0 ? cell.m / em : 0.0;
          lc.l1 += std::fabs(a - b);
        }
        // Peaks and centroids of the theta_r marginal.
        int imax_s = 0, imax_m = 0;
        double cs = 0.0, cm = 0.0;
        for (int i = 0; i < nt; ++i) {
          if (th[i].s1 > th[imax_s].s1) imax_s = i;
          if (th[i].m > th[imax_m].m) imax_m = i;
          cs += bin_centre(r.grid.theta_edges, i) * th[i].s1;
          cm += bin_centre(r.grid.theta_edges, i) * th[i].m;
        }
        lc.peak_sim = bin_centre(r.grid.theta_edges, imax_s);
        lc.peak_model = bin_centre(r.grid.theta_edges, imax_m);
        lc.centroid_sim = total.s1 > 0 ? cs / total.s1 : 0.0;
        lc.centroid_model = em > 0 ? cm / em : 0.0;
        // Standard error of a ratio of sums, by the delta method: the centroid
        // is sum t w / sum w over photons; its variance is
        // sum (t - c)^2 w^2 / (sum w)^2, estimated per bin from S2.
        double var = 0.0;
        for (int i = 0; i < nt; ++i) {
          const double d = bin_centre(r.grid.theta_edges, i) - lc.centroid_sim;
          var += d * d * th[i].s2;
        }
        lc.centroid_sim_error = total.s1 > 0 ? std::sqrt(var) / total.s1 : 0.0;
        lc.alpha_model = analytic::for_lobe(alpha, lobe);
        lc.measured_shift = lc.alpha_model + lc.centroid_sim - lc.centroid_model;
        lc.judged = std::max(es, em) >= o.min_lobe_energy && lc.bins.dof > 0;
        out.push_back(lc);
      }
    }
  }
  return out;
}

Selection select_bins(const sim::ResultFile& r, const Options& o) {
  Selection sel;
  for (std::size_t k = 0; k < r.configs(); ++k)
    for (int lobe = 0; lobe < r.lobes; ++lobe)
      for (int c = 0; c < r.channels; ++c) {
        if (!o.lobes.empty() && std::find(o.lobes.begin(), o.lobes.end(), lobe) == o.lobes.end()) continue;
        Selection::Block b{k, lobe, c, {}, {}};
        for (int i = 0; i < r.grid.n_theta(); ++i)
          for (int j = 0; j < r.grid.n_phi(); ++j) {
            const std::size_t idx = r.cell(k, lobe, i, j, c);
            const double s1 = r.weight_sum[idx], s2 = r.weight_sq_sum[idx];
            if (s2 > 0.0 && s1 * s1 / s2 >= o.min_effective) b.compared.push_back(idx);
            else b.rest.push_back(idx);
          }
        sel.blocks.push_back(std::move(b));
      }
  return sel;
}

std::vector<double> normalised_residuals(const sim::ResultFile& r, const Selection& sel,
                                         const std::vector<std::vector<double>>& model_bins,
                                         const Options& o) {
  std::vector<double> out;
  for (const Selection::Block& b : sel.blocks) {
    const double n = static_cast<double>(r.photons[b.k]);
    const std::vector<double>& mb = model_bins.at(b.k);
    const std::size_t base = b.k * r.bin_cells();
    Cell total, rest;
    for (std::size_t idx : b.compared) total.add({r.weight_sum[idx], r.weight_sq_sum[idx], 0.0});
    for (std::size_t idx : b.rest) {
      const Cell c{r.weight_sum[idx], r.weight_sq_sum[idx], mb[idx - base]};
      total.add(c);
      rest.add(c);
    }
    const double ratio = total.s1 > 0.0 ? total.s2 / total.s1 : 1.0;
    for (std::size_t idx : b.compared) {
      const Cell c{r.weight_sum[idx], r.weight_sq_sum[idx], mb[idx - base]};
      out.push_back((c.s1 / n - c.m) / std::sqrt(cell_variance(c, n, ratio, o.model_rel_error, false)));
    }
    // The rest cell always contributes (zero when both sides are empty) so
    // that the residual vector has a fixed length during a fit.
    const double var = cell_variance(rest, n, ratio, o.model_rel_error, true);
    out.push_back(var > 0.0 ? (rest.s1 / n - rest.m) / std::sqrt(var) : 0.0);
  }
  return out;
}

}  // namespace fiberlab::compare
