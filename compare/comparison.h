#pragma once
// Simulated histograms against a model's bin probabilities: both in the same
// currency (probability per bin with an uncertainty), per incident
// configuration k, lobe and channel. No physics here, only statistics.
//
// Statistics (SPEC sections 6 and 10), for one (k, lobe, channel):
// - P_b = S1_b / N with variance s_b^2 = (S2_b/N - P_b^2)/(N - 1) (the
//   simulation's), plus (q M_b)^2 for the model's bin integral M_b, q the
//   model's relative quadrature error (Options::model_rel_error).
// - Compared bins: effective sample size S1^2/S2 >= min_effective (30).
//   Every other bin is pooled into one "rest" cell (sum of S1, S2 and M over
//   them), which enters the chi-square as one more term when either side
//   has mass there: a model putting light where the simulation has (almost)
//   none is caught by it. dof = compared bins + rest cell (the model is not
//   fitted to this lobe; after --fit see fit.h).
// - L1 = sum |P_b / E_sim - M_b / E_model| over every bin (the normalised
//   distributions; 0..2).
// - Marginals: the same chi-square on the theta- and phi-marginals (sums
//   over phi, over theta of S1, S2, M), same selection rule.
// - Peak and centroid of the theta_r marginal (bin centres), simulated and
//   predicted; the simulation's centroid with its standard error. The
//   "measured shift" alpha_p + (centroid_sim - centroid_model) is the theta_r
//   shift the model would need for its centroid to match (first order).
#include <optional>
#include <string>
#include <vector>

#include "sim/store/result_file.h"

namespace fiberlab::compare {

struct Options {
  double min_effective = 30.0;   // S1^2/S2 per compared bin (SPEC s10)
  double model_rel_error = 1e-4; // relative quadrature error assumed for M_b
  double min_lobe_energy = 1e-4; // lobes with less simulated and predicted energy are not judged
  // The lobes a fit's selection takes (tally lobe indices; empty: every
  // lobe): select_bins() leaves the others out, so a fit judges and fits
  // only these (`fit: {lobes: [...]}`, `compare --fit-lobes`).
  std::vector<int> lobes;
};

// How check_options names the options in its messages: the command line's
// flags (--min-energy) or the Python keywords (min_energy).
enum class OptionSpelling { CommandLine, Python };
// Each option finite and in its range, max_chi2 (when given) too; otherwise
// fiberlab::Error naming the option and the range: min_effective > 0,
// model_rel_error in [0, 1] (a relative error), min_lobe_energy in [0, 1)
// (a lobe's energy is a fraction of the incident power: 1 or more judges
// nothing), max_chi2 > 0.
void check_options(const Options& o, std::optional<double> max_chi2, OptionSpelling spelling);

struct ChiSquare {
  double chi2 = 0.0;
  int dof = 0;
  double per_dof() const { return dof > 0 ? chi2 / dof : 0.0; }
};

struct LobeComparison {
  std::size_t k = 0;
  int lobe = 0, channel = 0;
  double theta_i = 0.0, phi_i = 0.0;
  double sim_energy = 0.0, sim_error = 0.0, model_energy = 0.0;
  double energy_z = 0.0;  // (model - sim) / sim_error
  ChiSquare bins, theta_marginal, phi_marginal;
  int compared_bins = 0;
  double rest_sim = 0.0, rest_model = 0.0;  // mass in the pooled rest cell
  double l1 = 0.0;
  double peak_sim = 0.0, peak_model = 0.0;          // theta_r, radians
  double centroid_sim = 0.0, centroid_sim_error = 0.0, centroid_model = 0.0;
  double alpha_model = 0.0;                          // the model's alpha_p
  double measured_shift = 0.0;                       // alpha_p + centroid_sim - centroid_model
  bool judged = false;                               // enough energy to be judged
};

// `model_bins`: per k, [lobe][theta][phi][channel] as predict_bins() gives.
// `alpha`: the model's shift of theta_r per lobe (for the shift column).
std::vector<LobeComparison> compare(const sim::ResultFile& result,
                                    const std::vector<std::vector<double>>& model_bins,
                                    const std::vector<double>& alpha, const Options& options = {});

// The compared bins of every (k, lobe, channel): a fixed selection, so that a
// fit's chi-square is a continuous function of the parameters.
struct Selection {
  // For each (k, lobe, channel) block: indices of compared cells (into the
  // result's weight_sum) and the rest cells.
  struct Block {
    std::size_t k;
    int lobe, channel;
    std::vector<std::size_t> compared, rest;
  };
  std::vector<Block> blocks;
};
Selection select_bins(const sim::ResultFile& result, const Options& options = {});

// Normalised residuals (P - M)/sigma over a selection: each block's compared
// bins and its rest cell (skipped when both sides have no mass there).
// model_bins in the layout of compare().
std::vector<double> normalised_residuals(const sim::ResultFile& result, const Selection& sel,
                                         const std::vector<std::vector<double>>& model_bins,
                                         const Options& options = {});

}  // namespace fiberlab::compare
