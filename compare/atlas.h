#pragma once
// `fiberlab atlas`: how wrong each registered model is for each physical
// fiber of a sweep (compare/atlas_config.h), per lobe, before and after
// fitting the model's free parameters (compare/fit.h, free_fit_keys()).
//
// Per fiber: one simulation (every theta_i of the sweep) run in process;
// then for every model of the config (every registered model by default,
// so a model added to analytic/model_registry appears here by itself):
// - its parameters for the fiber (the model's physical defaults,
//   ModelInfo::from_fiber); a model that refuses the fiber (e.g. a circular
//   model on an elliptical one) is recorded as not applicable, with why;
// - the comparison of compare/comparison.h with those ("before");
// - one joint fit of every free parameter over all theta_i and channels
//   (a model's parameters describe the fiber, not a lighting direction), and
//   the comparison again ("after"). A model whose table marks no parameter
//   free (exact) has no "after";
// - with fit.per_lobe, then each lobe of the fit (fit.lobes, default every
//   lobe) fitted alone from the joint fit's values (compare::fit_each_lobe:
//   a per-lobe list key such as beta_long becomes the lobe's own entry
//   beta_long[p], scale_tilt the lobe's shift alpha[p], scalars stay; each fit
//   judges that lobe's bins only), and that lobe compared again with its own
//   values ("after per-lobe fit"). The fit starts where the joint fit ended
//   and takes only steps that lower that lobe's chi-square, so a lobe's
//   chi-square after it is at most the one after the joint fit. A model
//   whose free keys have no per-lobe entry (a scalar roughness) is not
//   fitted lobe by lobe, and its per-lobe status says so.
// The statistics are compare/'s own; the atlas adds none.
#include <functional>
#include <string>
#include <vector>

#include "compare/atlas_config.h"
#include "compare/comparison.h"
#include "compare/fit.h"

namespace fiberlab::compare {

struct AtlasModelResult {
  std::string model;   // the entry's name (a registered model or a variant)
  std::string status;  // "fitted", "not fitted: ...", "not applicable: ..."
  bool applicable = false, fitted = false;
  std::string params_before, params_after;  // "key=value ..." (command-line units)
  std::vector<LobeComparison> before, after;  // per (k, lobe, channel), compare()'s order
  FitResult fit;       // keys empty when not fitted
  double seconds = 0.0;
  // fit.per_lobe: "" without it; else "fitted lobe by lobe" or "not fitted
  // lobe by lobe: why".
  std::string lobe_fit_status;
  std::vector<LobeFit> lobe_fits;          // per lobe of the fit, in fit.lobes order
  std::vector<std::string> lobe_fit_lines;  // per lobe fit: its status line (as `status` for the joint fit)
  std::vector<LobeComparison> after_lobe_fit;  // each fitted lobe's rows at its own fitted values
};

struct AtlasFiberResult {
  AtlasFiber fiber;
  std::vector<double> theta_i;        // radians, K
  int lobes = 0, channels = 0;
  std::vector<double> sim_energy, sim_error;  // K x L x C (the ledger's lobe energies)
  std::uint64_t photons = 0;          // per incident direction
  double sim_seconds = 0.0, fit_seconds = 0.0;
  std::vector<AtlasModelResult> models;
};

// Thrown when SIGINT/SIGTERM stopped the sweep (no output is written).
struct AtlasInterrupted {
  int signal = 0;
};

struct AtlasControl {
  int threads = 0;  // <= 0: OpenMP's default
  // One line at a time for stderr (fiber started, simulation progress, fit
  // iterations); may be empty.
  std::function<void(const std::string&)> progress;
};

// Simulates and judges one fiber. Throws AtlasInterrupted on a signal
// (install_interrupt_handlers() must have been called by the command).
AtlasFiberResult run_atlas_fiber(const AtlasConfig& config, std::size_t fiber, const AtlasControl& control);

// The parameters the entry `entry` of config.models (a registered model or
// a variant) starts from for `fiber`: its model's physical defaults for the
// fiber (ModelInfo::from_fiber) with the entry's fixed settings on top,
// checked by the model. Throws fiberlab::Error when
// the model refuses the fiber (then "not applicable").
analytic::ModelParameters atlas_start_params(const AtlasConfig& config, const AtlasFiber& fiber,
                                         const std::string& entry);

// Summary per fiber, model and lobe, over every theta_i and channel.
struct AtlasLobeSummary {
  double max_abs_energy_error = 0.0;     // max |E_model - E_sim| (fraction of incident light)
  double max_rel_energy_error = 0.0;     // max |E_model - E_sim| / E_sim over judged entries
  double chi2_before = 0.0, chi2_after = 0.0;
  int dof_before = 0, dof_after = 0;
  double max_abs_energy_error_after = 0.0;
  bool judged = false;
  // After the lobe's own fit (fit.per_lobe; lobe_fitted false otherwise).
  double chi2_lobe_fit = 0.0, max_abs_energy_error_lobe_fit = 0.0;
  int dof_lobe_fit = 0;
  bool lobe_fitted = false;
};
AtlasLobeSummary summarize_lobe(const AtlasModelResult& m, int lobe);

}  // namespace fiberlab::compare
