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
#include "compare/comparison.h"
#include "sim/result_file.h"

namespace fiberlab::compare {

// Reads / writes one fit key of ModelParams, in the key's units (degrees for
// angles). Throws fiberlab::Error for an unknown key. The keys shared by
// the built-in models' lists and scalars (eta, beta_long[p], scale_tilt, ...).
double get_parameter(const analytic::ModelParams& p, const std::string& key);
void set_parameter(analytic::ModelParams& p, const std::string& key, double value);
// The same for model `model_name`: a scalar of its table (number_param,
// e.g. chiang2016's beta_m, beta_n, alpha) through the table's own
// accessors, anything else as above. The fit uses these.
double get_parameter(const std::string& model_name, const analytic::ModelParams& p, const std::string& key);
void set_parameter(const std::string& model_name, analytic::ModelParams& p, const std::string& key,
                   double value);
// The closed range the fit keeps `key` in (the table's ParamSpec::fit_min,
// fit_max; widths at least 0.05 deg, the floor of set_parameter; scale_tilt
// that of the tilt shifts `alpha`).
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

struct FitResult {
  std::vector<std::string> keys;
  std::vector<double> start, value;
  std::vector<double> error;           // scaled by sqrt(max(1, chi2/dof))
  std::vector<double> error_unscaled;  // sqrt(diag((J^T W J)^-1))
  std::vector<bool> at_bound;          // the value sits on an end of fit_range()
  double chi2_start = 0.0, chi2 = 0.0;
  int residuals = 0, dof = 0, iterations = 0, evaluations = 0;
  bool converged = false;
  analytic::ModelParams params;  // at the minimum
  double per_dof() const { return dof > 0 ? chi2 / dof : 0.0; }
};

// `progress` (optional) receives one line per iteration (the CLI prints it
// on stderr: fits take minutes).
FitResult fit_model(const sim::ResultFile& result, const std::string& model_name,
                    const analytic::ModelParams& start, const std::vector<std::string>& keys,
                    const Options& options = {}, int max_iterations = 40,
                    const std::function<void(const std::string&)>& progress = {});

}  // namespace fiberlab::compare
