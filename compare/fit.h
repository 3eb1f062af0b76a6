#pragma once
// Weighted least-squares fit of model parameters to a simulated histogram
// (Levenberg-Marquardt with central-difference derivatives, Eigen).
//
// Residuals: the normalised residuals (P_b - M_b(theta)) / sigma_b of
// comparison.h over a selection of bins fixed before the fit (every
// incident configuration, lobe and channel of the result; bins with
// S1^2/S2 >= 30 one by one, the rest pooled per lobe). chi2 = |r|^2,
// dof = residuals - fitted parameters.
//
// Uncertainties: covariance (J^T W J)^-1 at the minimum (J the derivatives of
// the model's bin probabilities, W = diag(1/sigma^2)), scaled by
// max(1, chi2/dof): when the model does not describe the data within the
// noise (chi2/dof > 1), the errors grow as for any under-fitted least-squares
// problem (the PDG's scale factor); when it does they are the bare ones.
// Both are reported.
//
// Derivatives: central differences with a step of 2% of the value, at
// least 0.2% of the fit range (1e-3 in the key's units when the range is
// unbounded): the models' predictions are free of noise but not all of
// them are smooth on a finer scale (huang2022's bins are a fixed point set
// pushed through the model: a step must move many of its paths across bin
// edges for the difference to be the derivative, not a count of the few that
// crossed); the truncation error of a 2% central difference is ~1e-4
// relative for smooth models, far below what the damping absorbs.
//
// Stopping (checked after every accepted step): converged when chi2 fell by
// less than 1e-2 max(1, chi2/dof) (chi2 rises by max(1, chi2/dof) when a
// parameter moves by one of its scaled errors: this drop is a move of 0.1
// error) or every parameter moved by less than 1% of its current (scaled)
// error; converged also when no step lowers
// chi2 at any damping (a minimum, to the prediction's resolution). The
// result says which (stop_reason) and whether a parameter sits on a bound.
// Along a valley (an accepted step within 26 deg of the previous one) the
// step is doubled while chi2 keeps falling, up to 3 times: with a model that
// does not describe the data, Gauss-Newton steps are short there and the
// fit would otherwise crawl.
//
// Bounds: each value stays in the table's range (fit_range(); projected
// steps, a parameter held at a bound while the gradient points outwards).
// A value that ends on a bound is flagged (at_bound): its error is the
// curvature's, not a confidence interval.
//
// Keys (angles in degrees), each one of the model's own numeric parameters
// (its table, analytic/model_registry.h; another key is refused naming the
// model's fittable keys):
//   eta, k_g, beta_m, beta_n, ... (scalars: any number of the model's
//     table, e.g. chiang2016's beta_m, beta_n and alpha, its scalar tilt);
//   sigma_a (one common value for every channel),
//   sigma_a[c];
//   beta_long, beta_azim (one common value for every lobe: the list is
//     replaced by one entry); beta_long[p], beta_azim[p], alpha[p] (entry
//     p only, per lobe; the list is extended by its last entry as needed).
//     A bare `alpha` is refused: one common shift for every lobe moves R the
//     wrong way (R shifts by -2a, TT by +a); fit alpha[p] or scale_tilt;
//   scale_tilt (models with alpha): the physical cuticle tilt a, mapped to
//     every lobe's alpha by the shift rule of SPEC s7 (analytic::tilt_shifts:
//     R -2a, TT +a, TRT +4a, p >= 3: 0).
#include <functional>
#include <utility>
#include <string>
#include <vector>

#include "analytic/model.h"
#include "analytic/model_parameters.h"
#include "compare/comparison.h"
#include "sim/store/result_file.h"

namespace fiberlab::compare {

// Reads / writes one fit key of model `model_name`, in the key's units
// (degrees for angles), through its parameter table's accessors
// (analytic::ParamSpec get_number / get_entry): a scalar, a list entry
// NAME[p], or a list as one value (beta_long; alpha as scale_tilt). The value
// is stored as given (make_model() checks the table's range). Throws
// fiberlab::Error for a key the model cannot fit.
double get_parameter(const std::string& model_name, const analytic::ModelParameters& p, const std::string& key);
void set_parameter(const std::string& model_name, analytic::ModelParameters& p, const std::string& key,
                   double value);
// The closed range the fit keeps `key` in (the table's ParamSpec::fit_min,
// fit_max; scale_tilt that of the tilt shifts `alpha`).
std::pair<double, double> fit_range(const std::string& model_name, const std::string& key);
// The keys that fit every free parameter of the model's table
// (ParamSpec::free), one number each, as a user sets them: a scalar as
// itself, a per-lobe list as one common value (`beta_long`), a per-lobe
// list of tilt shifts `alpha` through the physical `scale_tilt`. Empty when
// the table marks none free (e.g. `exact`).
std::vector<std::string> free_fit_keys(const std::string& model_name);
// Refuses (fiberlab::Error) a key that model `model_name` cannot fit.
void check_fit_key(const std::string& model_name, const std::string& key);
// Every key checked, and each parameter fitted once: a key repeated, a list
// with one of its entries (beta_long and beta_long[0]), or scale_tilt with an
// alpha[p] (both move alpha) is refused, naming both keys.
void check_fit_keys(const std::string& model_name, const std::vector<std::string>& keys);

// How a fit ended. Converged: a step changed chi2 by a negligible amount, or
// moved every parameter by a negligible part of its error, or no downhill
// step existed at any damping. AtBound: converged with a parameter held on
// an end of fit_range(). NotConverged: the iteration cap came first.
// NotFitted: no key changes any fitted residual (every derivative at the
// start is exactly 0, e.g. a per-lobe fit of a lobe the model predicts
// nothing in, or whose prediction none of the keys enters): there is no fit,
// the values stay at the start, their errors are NaN, chi2 is the start's
// over dof = residuals, and no iteration is taken.
enum class FitOutcome { Converged, AtBound, NotConverged, NotFitted };
// "converged", "at a bound", "not converged", "not fitted"
const char* outcome_name(FitOutcome o);
// The stop reason of a NotFitted fit of one lobe.
inline constexpr const char* kNoKeyActsOnLobe = "no free parameter acts on this lobe";

struct FitResult {
  std::vector<std::string> keys;
  std::vector<double> start, value;
  std::vector<double> error;           // scaled by sqrt(max(1, chi2/dof))
  std::vector<double> error_unscaled;  // sqrt(diag((J^T W J)^-1))
  std::vector<bool> at_bound;          // the value sits on an end of fit_range()
  double chi2_start = 0.0, chi2 = 0.0;
  int residuals = 0, dof = 0, iterations = 0, evaluations = 0;
  bool converged = false;  // outcome is Converged or AtBound
  FitOutcome outcome = FitOutcome::NotConverged;
  std::string stop_reason;  // one line: why the fit stopped (the test that ended it, with its numbers)
  analytic::ModelParameters params;  // at the minimum
  double per_dof() const { return dof > 0 ? chi2 / dof : 0.0; }
};

// Lobe indices of lobe names (one of `known`, the lobe axis's names: R, TT,
// TRT, ..., the last lobe by p's "p>=N", `scattered` with a medulla; or a
// lobe index); throws fiberlab::Error naming `what` (the flag or config key)
// and the allowed names.
std::vector<int> parse_fit_lobes(const std::vector<std::string>& names, const std::vector<std::string>& known,
                                 const std::string& what);

// The keys of a per-lobe fit of lobe `lobe`: a per-lobe list key of the
// model (beta_long, beta_azim) becomes that lobe's entry (beta_long[lobe]),
// the physical scale_tilt of a model with per-lobe shifts becomes the
// lobe's shift alpha[lobe]; scalars stay (fitted to that lobe's bins only).
std::vector<std::string> per_lobe_keys(const std::string& model_name, const std::vector<std::string>& keys,
                                       int lobe);

// `progress` (optional) receives one line per iteration (the CLI prints it
// on stderr: fits take minutes).
FitResult fit_model(const sim::ResultFile& result, const std::string& model_name,
                    const analytic::ModelParameters& start, const std::vector<std::string>& keys,
                    const Options& options = {}, int max_iterations = 40,
                    const std::function<void(const std::string&)>& progress = {});

// The start of a per-lobe fit with keys `lobe_keys` (per_lobe_keys()):
// `start` with each per-lobe list those keys move entry by entry
// (beta_long[p]) written out with one entry per predicted lobe, each the
// value that lobe had (a list's last entry applies to every larger p,
// analytic/model_params.h). The same model, whose fitted entry then moves
// only its own lobe, so the fit's params predict every other lobe as `start`.
analytic::ModelParameters lobe_fit_start(const std::string& model_name, const analytic::ModelParameters& start,
                                         const std::vector<std::string>& lobe_keys);

// One fit per lobe: for each lobe of options.lobes (every lobe of the
// result when empty), fit_model() on that lobe's bins alone with
// per_lobe_keys(model, keys, lobe), from lobe_fit_start() of the same start:
// each LobeFit's params hold the fitted entry for its lobe and the start's
// values for the others (predicting with them is the start on every other lobe).
struct LobeFit {
  int lobe = 0;
  FitResult fit;
};
std::vector<LobeFit> fit_each_lobe(const sim::ResultFile& result, const std::string& model_name,
                                   const analytic::ModelParameters& start, const std::vector<std::string>& keys,
                                   const Options& options = {}, int max_iterations = 40,
                                   const std::function<void(const std::string&)>& progress = {});

}  // namespace fiberlab::compare
