#include "compare/fit.h"

#include <fmt/core.h>
#include <fmt/ranges.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <tuple>

#include "common/error.h"
#include "common/file_schema.h"
#include "common/units.h"
#include "analytic/model_registry.h"
#include "analytic/physical_defaults.h"
#include "compare/models.h"

namespace fiberlab::compare {

namespace {

struct Key {
  std::string name;
  int index = -1;  // -1: the whole list (or a scalar)
};

Key parse_key(const std::string& key) {
  Key k;
  const auto open = key.find('[');
  if (open == std::string::npos) {
    k.name = key;
    return k;
  }
  const auto close = key.find(']', open);
  if (close == std::string::npos || close != key.size() - 1)
    throw Error(fmt::format("--fit key '{}': expected NAME or NAME[INDEX]", key));
  k.name = key.substr(0, open);
  try {
    k.index = std::stoi(key.substr(open + 1, close - open - 1));
  } catch (const std::exception&) {
    throw Error(fmt::format("--fit key '{}': the index is not an integer", key));
  }
  if (k.index < 0) throw Error(fmt::format("--fit key '{}': negative index", key));
  return k;
}

// The table entry a fit key moves: the spec named `k.name`, or the list
// whose whole value has that fit key (alpha's `scale_tilt`); nullptr if none.
const analytic::ParamSpec* spec_of(const std::string& model_name, const Key& k) {
  const analytic::ParamTable& table = analytic::model_info(model_name).params;
  if (k.index < 0)
    for (const analytic::ParamSpec& s : table)
      if (!s.whole_fit_key.empty() && s.whole_fit_key == k.name) return &s;
  return analytic::find_param(table, k.name);
}
// A fit moves real numbers: integers (lobes, quadrature_points) and choices stay as set.
bool is_real(const analytic::ParamSpec& spec) { return spec.unit != "integer" && spec.unit != "choice"; }
bool is_list(const analytic::ParamSpec& spec) { return spec.get_entry && spec.set_entry && is_real(spec); }
bool is_scalar(const analytic::ParamSpec& spec) { return spec.get_number && spec.set_number && is_real(spec); }
// The key a fit gives the spec's whole value.
const std::string& whole_key(const analytic::ParamSpec& spec) {
  return spec.whole_fit_key.empty() ? spec.key : spec.whole_fit_key;
}
// The spec `key` moves, in its table, as a fit may move it (a number: a
// scalar, a list entry NAME[p], or a list's whole value by its fit key);
// fiberlab::Error naming the model's fittable keys otherwise.
const analytic::ParamSpec& fit_spec(const std::string& model_name, const std::string& key) {
  const Key k = parse_key(key);
  const analytic::ParamSpec* spec = spec_of(model_name, k);
  const bool ok = spec && (k.index < 0 ? (is_scalar(*spec) || (is_list(*spec) && whole_key(*spec) == k.name))
                                       : is_list(*spec) && k.name == spec->key);
  if (ok) return *spec;
  // The numeric keys in table order (a list also per entry, NAME[p]), then
  // the lists' whole fit keys.
  std::string fittable, whole;
  for (const analytic::ParamSpec& s : analytic::model_info(model_name).params) {
    if (is_scalar(s) || is_list(s)) fittable += (fittable.empty() ? "" : ", ") + s.key;
    if (is_list(s) && !s.whole_fit_key.empty()) whole += ", " + s.whole_fit_key;
  }
  fittable += whole;
  if (spec && is_list(*spec) && k.index < 0 && k.name == spec->key)
    throw Error(fmt::format("--fit {}: one common shift for every lobe moves R the wrong way; fit "
                            "{}[p] per lobe (e.g. {}[0],{}[1]) or the physical {}",
                            key, k.name, k.name, k.name, spec->whole_fit_key));
  throw Error(fmt::format("--fit {}: model {} cannot fit '{}'; fittable keys: {} (lists per lobe as NAME[p])",
                          key, model_name, key, fittable));
}

}  // namespace

double get_parameter(const std::string& model_name, const analytic::ModelParameters& p, const std::string& key) {
  const analytic::ParamSpec& spec = fit_spec(model_name, key);
  const Key k = parse_key(key);
  return is_list(spec) ? spec.get_entry(p, k.index) : spec.get_number(p);
}

void set_parameter(const std::string& model_name, analytic::ModelParameters& p, const std::string& key,
                   double value) {
  const analytic::ParamSpec& spec = fit_spec(model_name, key);
  const Key k = parse_key(key);
  if (is_list(spec)) spec.set_entry(p, k.index, value);
  else spec.set_number(p, value);
}

std::pair<double, double> fit_range(const std::string& model_name, const std::string& key) {
  const analytic::ParamSpec& spec = fit_spec(model_name, key);
  return {spec.fit_min, spec.fit_max};
}

std::vector<std::string> free_fit_keys(const std::string& model_name) {
  std::vector<std::string> keys;
  // A list as one number: its whole fit key (alpha's physical scale_tilt,
  // SPEC s7's rule), any other list as one common value.
  for (const analytic::ParamSpec& s : analytic::model_info(model_name).params)
    if (s.free) keys.push_back(whole_key(s));
  return keys;
}

void check_fit_key(const std::string& model_name, const std::string& key) { fit_spec(model_name, key); }

void check_fit_keys(const std::string& model_name, const std::vector<std::string>& keys) {
  for (std::size_t i = 0; i < keys.size(); ++i) {
    const analytic::ParamSpec* sb = &fit_spec(model_name, keys[i]);
    const Key b = parse_key(keys[i]);
    for (std::size_t j = 0; j < i; ++j) {
      const Key a = parse_key(keys[j]);
      // The same table entry, the same entry of it or the whole of it
      // (scale_tilt and alpha[p] both move alpha).
      if (&fit_spec(model_name, keys[j]) == sb && (a.index == b.index || a.index < 0 || b.index < 0))
        throw Error(fmt::format("--fit {}: {} fits the same parameter as {} (give each parameter once)",
                                fmt::join(keys, ","), keys[i], keys[j]));
    }
  }
}

std::vector<int> parse_fit_lobes(const std::vector<std::string>& names, const std::vector<std::string>& known,
                                 const std::string& what) {
  const int lobes = static_cast<int>(known.size());
  std::vector<int> out;
  for (const std::string& name : names) {
    int found = -1;
    for (int l = 0; l < lobes; ++l)
      if (name == known[l] || name == std::to_string(l)) found = l;
    if (found < 0)
      throw Error(fmt::format("{}: unknown lobe '{}' (allowed: {}, or an index 0..{})", what, name,
                              join_names(known), lobes - 1));
    if (std::find(out.begin(), out.end(), found) != out.end())
      throw Error(fmt::format("{}: lobe '{}' given twice", what, name));
    out.push_back(found);
  }
  if (out.empty()) throw Error(fmt::format("{}: no lobe given (allowed: {})", what, join_names(known)));
  return out;
}

std::vector<std::string> per_lobe_keys(const std::string& model_name, const std::vector<std::string>& keys,
                                       int lobe) {
  std::vector<std::string> out;
  for (const std::string& key : keys) {
    const Key k = parse_key(key);
    const analytic::ParamSpec* spec = spec_of(model_name, k);
    if (k.index < 0 && spec && spec->per_lobe && is_list(*spec))
      out.push_back(fmt::format("{}[{}]", spec->key, lobe));
    else
      out.push_back(key);
  }
  return out;
}

const char* outcome_name(FitOutcome o) {
  switch (o) {
    case FitOutcome::Converged: return "converged";
    case FitOutcome::AtBound: return "at a bound";
    case FitOutcome::NotConverged: return "not converged";
    case FitOutcome::NotFitted: return "not fitted";
  }
  return "not converged";
}

namespace {

constexpr double kChi2DropTolerance = 1e-2;  // of max(1, chi2/dof): fit.h "Stopping"
constexpr int kExtensions = 3;               // doublings of a step along a valley: fit.h
constexpr int kDampings = 12;                // tenfold damping increases tried per iteration

Eigen::VectorXd to_vector(const std::vector<double>& r) {
  return Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(r.data(), static_cast<long>(r.size())));
}

// What a fit evaluates: the model with the fitted keys at x (each kept in
// its fit_range()), its normalised residuals over the selected bins, and
// their Jacobian.
class FitProblem {
 public:
  FitProblem(const sim::ResultFile& result, const std::string& model_name, const analytic::ModelParameters& start,
             const std::vector<std::string>& keys, const Options& options)
      : result_(result), model_(model_name), start_(start), keys_(keys), options_(options) {
    const int n = static_cast<int>(keys.size());
    lo_.resize(n);
    hi_.resize(n);
    for (int j = 0; j < n; ++j) {
      std::tie(lo_[j], hi_[j]) = fit_range(model_name, keys[j]);
      x0_.push_back(std::clamp(get_parameter(model_name, start, keys[j]), lo_[j], hi_[j]));
    }
    for (int l : options.lobes)
      if (l < 0 || l >= result.lobes)
        throw Error(fmt::format("--fit: lobe {} is not in the result (its lobes are 0..{})", l, result.lobes - 1));
    sel_ = select_bins(result, options);
  }

  int n() const { return static_cast<int>(keys_.size()); }
  const std::vector<std::string>& keys() const { return keys_; }
  // The start, clamped into the ranges.
  const std::vector<double>& x0() const { return x0_; }
  bool at_bound(int j, double x) const {
    const double tol = 1e-9 * (1.0 + std::fabs(x));
    return x <= lo_[j] + tol || x >= hi_[j] - tol;
  }

  // Projected Levenberg-Marquardt: every trial point is clamped into the
  // table's ranges (fit_range), so the model is never asked for a value it
  // refuses; derivatives at a bound are one-sided.
  Eigen::VectorXd project(Eigen::VectorXd x) const {
    for (int j = 0; j < n(); ++j) x[j] = std::clamp(x[j], lo_[j], hi_[j]);
    return x;
  }

  // Active set: a parameter at a bound whose descent direction (-g) points
  // out of its range is held there for this iteration.
  std::vector<bool> held(const Eigen::VectorXd& x, const Eigen::VectorXd& g) const {
    std::vector<bool> h(n(), false);
    for (int j = 0; j < n(); ++j) h[j] = (x[j] <= lo_[j] && g[j] > 0.0) || (x[j] >= hi_[j] && g[j] < 0.0);
    return h;
  }

  analytic::ModelParameters params_at(const Eigen::VectorXd& x) const {
    analytic::ModelParameters p = start_;
    for (int j = 0; j < n(); ++j) set_parameter(model_, p, keys_[j], x[j]);
    return p;
  }

  Eigen::VectorXd residuals(const Eigen::VectorXd& x) const {
    const auto model = compare::make_model(model_, params_at(x));
    return to_vector(normalised_residuals(result_, sel_, predict_result(*model, result_), options_));
  }

  // Central differences (one-sided at a bound), m residuals by n keys.
  Eigen::MatrixXd jacobian(const Eigen::VectorXd& x, long m) const {
    std::vector<Eigen::VectorXd> trial(2 * n(), x);
    for (int j = 0; j < n(); ++j) {
      const double h = step(j, x[j]);
      trial[2 * j][j] = std::min(x[j] + h, hi_[j]);
      trial[2 * j + 1][j] = std::max(x[j] - h, lo_[j]);
    }
    const auto predicted = predict_all(trial);
    Eigen::MatrixXd J(m, n());
    for (int j = 0; j < n(); ++j) {
      const Eigen::VectorXd rp = to_vector(normalised_residuals(result_, sel_, predicted[2 * j], options_));
      const Eigen::VectorXd rm = to_vector(normalised_residuals(result_, sel_, predicted[2 * j + 1], options_));
      // set_parameter may clamp (beta floor): use the actual difference.
      const double dx = get_parameter(model_, params_at(trial[2 * j]), keys_[j]) -
                        get_parameter(model_, params_at(trial[2 * j + 1]), keys_[j]);
      J.col(j) = (rp - rm) / (dx != 0.0 ? dx : 2.0 * step(j, x[j]));
    }
    return J;
  }

 private:
  // A difference step in the key's units (degrees for angles), sized as
  // fit.h says.
  double step(int j, double x) const {
    const double width = hi_[j] - lo_[j];
    const double floor = std::isfinite(width) ? 2e-3 * width : 1e-3;
    double h = std::max(2e-2 * std::fabs(x), floor);
    if (std::isfinite(width)) h = std::min(h, 0.1 * width);
    return h;
  }

  // The trial points' predictions, [trial][configuration]: the trials x K
  // independent model evaluations (K incident configurations) in one
  // parallel loop keep every thread busy (a loop over the n columns leaves
  // threads idle when n is small or not a multiple of them). Each
  // evaluation is deterministic and the residuals are formed afterwards in
  // a fixed order, so the Jacobian is the same for any thread count.
  std::vector<std::vector<std::vector<double>>> predict_all(const std::vector<Eigen::VectorXd>& trial) const {
    const long T = static_cast<long>(trial.size()), K = static_cast<long>(result_.configs());
    std::vector<std::unique_ptr<analytic::Model>> models(T);
    for (long t = 0; t < T; ++t) models[t] = compare::make_model(model_, params_at(trial[t]));
    std::vector<std::vector<std::vector<double>>> predicted(T, std::vector<std::vector<double>>(K));
    std::string error;
#pragma omp parallel for schedule(dynamic)
    for (long t = 0; t < T * K; ++t) {
      try {
        predicted[t / K][t % K] = predict_config(*models[t / K], result_, static_cast<std::size_t>(t % K));
      } catch (const std::exception& e) {
#pragma omp critical
        error = e.what();
      }
    }
    if (!error.empty()) throw Error(error);
    return predicted;
  }

  const sim::ResultFile& result_;
  const std::string& model_;
  const analytic::ModelParameters& start_;
  const std::vector<std::string>& keys_;
  const Options& options_;
  std::vector<double> lo_, hi_, x0_;
  Selection sel_;
};

// Where the iteration stands: the point, its residuals, chi-square and
// Jacobian, the damping, and the last accepted step.
struct Iterate {
  Eigen::VectorXd x, r;
  double chi2 = 0.0;
  Eigen::MatrixXd J;
  double lambda = 1e-3;
  Eigen::VectorXd last_step;
  std::string last_move;  // the last accepted step, for a fit stopped by the cap
};

// Parameter errors at J (scaled by sqrt(max(1, chi2/dof)), as the result's):
// the yardstick of a step.
Eigen::VectorXd parameter_errors(const Eigen::MatrixXd& J, double chi2, int dof) {
  const Eigen::MatrixXd cov = (J.transpose() * J).completeOrthogonalDecomposition().pseudoInverse();
  Eigen::VectorXd e(J.cols());
  for (int j = 0; j < J.cols(); ++j) e[j] = std::sqrt(std::max(0.0, cov(j, j)) * std::max(1.0, chi2 / dof));
  return e;
}

// The damped Gauss-Newton target from x, projected into the ranges; a held
// parameter's row and column decoupled, so the others can still move.
Eigen::VectorXd damped_target(const FitProblem& problem, const Eigen::VectorXd& x, const Eigen::MatrixXd& A,
                              const Eigen::VectorXd& g, const std::vector<bool>& held, double lambda) {
  const int n = problem.n();
  Eigen::MatrixXd Ad = A;
  for (int j = 0; j < n; ++j) Ad(j, j) += lambda * std::max(A(j, j), 1e-12);
  Eigen::VectorXd gh = g;
  for (int j = 0; j < n; ++j)
    if (held[j]) {
      Ad.row(j).setZero();
      Ad.col(j).setZero();
      Ad(j, j) = 1.0;
      gh[j] = 0.0;
    }
  return problem.project(x + Ad.ldlt().solve(-gh));
}

// A valley: with large residuals (a model that does not describe the data)
// J^T J underrates how far chi2 keeps falling, and successive steps are
// short and point the same way. Then the step just taken (`step`, from
// `from`) is doubled while chi2 keeps falling, at most kExtensions
// evaluations, each further fall added to `drop`; `step` becomes the whole
// move.
void extend_along_valley(const FitProblem& problem, Iterate& it, const Eigen::VectorXd& from,
                         Eigen::VectorXd& step, double& drop, FitResult& fr) {
  const double norms = step.norm() * it.last_step.norm();
  if (!(norms > 0.0 && step.dot(it.last_step) > 0.9 * norms)) return;
  Eigen::VectorXd ahead = step;
  for (int e = 0; e < kExtensions; ++e) {
    ahead *= 2.0;
    const Eigen::VectorXd xe = problem.project(it.x + ahead);
    if (xe == it.x) break;
    const Eigen::VectorXd re = problem.residuals(xe);
    ++fr.evaluations;
    const double chi2e = re.squaredNorm();
    if (!(chi2e < it.chi2)) break;
    drop += it.chi2 - chi2e;
    it.x = xe;
    it.r = re;
    it.chi2 = chi2e;
  }
  step = it.x - from;
}

// The largest component of `step` in units of its parameter's error.
double largest_step_in_errors(const Eigen::VectorXd& step, const Eigen::VectorXd& err) {
  double out = 0.0;
  for (int j = 0; j < step.size(); ++j)
    out = std::max(out, err[j] > 0.0 ? std::fabs(step[j]) / err[j] : (step[j] != 0.0 ? HUGE_VAL : 0.0));
  return out;
}

// The stopping test after an accepted step (fit.h "Stopping"). A chi2
// change of S = max(1, chi2/dof) moves the parameters by one (scaled)
// error: for a model that does not describe the data (S >> 1) the errors
// are scaled by sqrt(S). A drop below 1e-2 S is a move of 0.1 error: what is
// left to gain is far below the errors (fits of wrong models stop there
// instead of polishing digits).
void test_convergence(double drop, double step_in_errors, Iterate& it, FitResult& fr) {
  const double unit = std::max(1.0, it.chi2 / fr.dof);
  it.last_move = fmt::format("chi2 fell by {:.3g} (tolerance {:.3g}), the largest step {:.3g} errors", drop,
                             kChi2DropTolerance * unit, step_in_errors);
  if (drop < kChi2DropTolerance * unit) {
    fr.converged = true;
    fr.stop_reason =
        fmt::format("chi2 fell by {:.3g} < {:.3g} (1e-2 max(1, chi2/dof))", drop, kChi2DropTolerance * unit);
  } else if (step_in_errors < 1e-2) {
    fr.converged = true;
    fr.stop_reason = fmt::format("every step below 1% of its parameter's error (largest {:.3g})", step_in_errors);
  }
}

// One Levenberg-Marquardt iteration: the damping is raised tenfold until a
// step lowers chi2 (at most kDampings tries), then lowered tenfold. Returns
// whether a step was taken (then the stopping test has run).
bool take_step(const FitProblem& problem, Iterate& it, FitResult& fr) {
  const Eigen::MatrixXd A = it.J.transpose() * it.J;
  const Eigen::VectorXd g = it.J.transpose() * it.r;
  const std::vector<bool> held = problem.held(it.x, g);
  const Eigen::VectorXd err = parameter_errors(it.J, it.chi2, fr.dof);
  for (int tries = 0; tries < kDampings; ++tries) {
    const Eigen::VectorXd xn = damped_target(problem, it.x, A, g, held, it.lambda);
    Eigen::VectorXd step = xn - it.x;
    const Eigen::VectorXd rn = problem.residuals(xn);
    ++fr.evaluations;
    const double chi2n = rn.squaredNorm();
    if (!(chi2n < it.chi2)) {
      it.lambda *= 10.0;
      continue;
    }
    double drop = it.chi2 - chi2n;
    const Eigen::VectorXd from = it.x;
    it.x = xn;
    it.r = rn;
    it.chi2 = chi2n;
    it.lambda = std::max(it.lambda / 10.0, 1e-9);
    extend_along_valley(problem, it, from, step, drop, fr);
    it.last_step = step;
    test_convergence(drop, largest_step_in_errors(step, err), it, fr);
    return true;
  }
  return false;
}

// Values, errors, bounds and outcome at the last point.
void finish(const FitProblem& problem, const Iterate& it, int max_iterations, FitResult& fr) {
  if (!fr.converged)
    fr.stop_reason = max_iterations == 0 ? "no iterations allowed (max_iterations = 0)"
                                         : fmt::format("stopped at the iteration cap ({}): last step: {}",
                                                       max_iterations, it.last_move);
  fr.chi2 = it.chi2;
  const Eigen::MatrixXd cov = (it.J.transpose() * it.J).inverse();
  const double scale = std::sqrt(std::max(1.0, fr.per_dof()));
  for (int j = 0; j < problem.n(); ++j) {
    fr.value.push_back(it.x[j]);
    const double e = std::sqrt(std::max(0.0, cov(j, j)));
    fr.error_unscaled.push_back(e);
    fr.error.push_back(e * scale);
    fr.at_bound.push_back(problem.at_bound(j, it.x[j]));
  }
  const bool bound = std::find(fr.at_bound.begin(), fr.at_bound.end(), true) != fr.at_bound.end();
  fr.outcome = !fr.converged ? FitOutcome::NotConverged : bound ? FitOutcome::AtBound : FitOutcome::Converged;
  fr.params = problem.params_at(it.x);
}

// Whether no key changes any residual: every derivative exactly 0 (the
// model's prediction of the fitted bins does not depend on the keys; a
// difference of exactly 0 is no rounding: a key that enters the prediction
// changes some bits of it).
bool no_key_acts(const Eigen::MatrixXd& J) { return J.size() > 0 && (J.array() == 0.0).all(); }

// The result of a fit that moves nothing (FitOutcome::NotFitted, fit.h).
void finish_not_fitted(const FitProblem& problem, const Iterate& it, const Options& options, FitResult& fr) {
  fr.outcome = FitOutcome::NotFitted;
  fr.converged = false;
  fr.stop_reason = options.lobes.size() == 1 ? kNoKeyActsOnLobe : "no free parameter acts on the fitted lobes";
  fr.dof = fr.residuals;
  fr.chi2 = fr.chi2_start;
  for (int j = 0; j < problem.n(); ++j) {
    fr.value.push_back(it.x[j]);
    fr.error.push_back(std::nan(""));
    fr.error_unscaled.push_back(std::nan(""));
    fr.at_bound.push_back(false);
  }
  fr.params = problem.params_at(it.x);
}

std::string iteration_line(const FitProblem& problem, const Iterate& it, const FitResult& fr) {
  std::string values;
  for (int j = 0; j < problem.n(); ++j) values += fmt::format(" {}={:.6g}", problem.keys()[j], it.x[j]);
  return fmt::format("fit: iteration {}, chi2/dof {:.4f}, {} model evaluations,{}", fr.iterations + 1,
                     it.chi2 / fr.dof, fr.evaluations, values);
}

}  // namespace

FitResult fit_model(const sim::ResultFile& result, const std::string& model_name,
                    const analytic::ModelParameters& start, const std::vector<std::string>& keys,
                    const Options& options, int max_iterations,
                    const std::function<void(const std::string&)>& progress) {
  if (keys.empty()) throw Error("--fit: no parameters given");
  check_fit_keys(model_name, keys);
  const FitProblem problem(result, model_name, start, keys, options);
  const int n = problem.n();
  FitResult fr;
  fr.keys = keys;
  fr.start = problem.x0();

  Iterate it;
  it.x = to_vector(fr.start);
  it.r = problem.residuals(it.x);
  ++fr.evaluations;
  const long m = it.r.size();
  fr.residuals = static_cast<int>(m);
  fr.chi2_start = it.r.squaredNorm();
  it.chi2 = fr.chi2_start;
  it.J = problem.jacobian(it.x, m);
  fr.evaluations += 2 * n;
  if (no_key_acts(it.J)) {
    finish_not_fitted(problem, it, options, fr);
    if (progress) progress(fmt::format("fit: {} residuals, not fitted: {}", m, fr.stop_reason));
    return fr;
  }
  fr.dof = static_cast<int>(m) - n;
  if (fr.dof <= 0) throw Error(fmt::format("--fit: {} residuals for {} parameters", m, n));
  if (progress)
    progress(fmt::format("fit: {} residuals, {} parameters, start chi2/dof {:.4f}; each iteration costs {} "
                         "model evaluations",
                         m, n, fr.chi2_start / fr.dof, 2 * n + 1));
  it.last_step = Eigen::VectorXd::Zero(n);
  for (fr.iterations = 0; fr.iterations < max_iterations; ++fr.iterations) {
    const bool improved = take_step(problem, it, fr);
    if (progress) progress(iteration_line(problem, it, fr));
    if (!improved) {
      fr.converged = true;  // no downhill step at any damping: at the minimum
      fr.stop_reason = "no step lowers chi2 at any damping (a minimum, to the prediction's resolution)";
      ++fr.iterations;
      break;
    }
    it.J = problem.jacobian(it.x, m);
    fr.evaluations += 2 * n;
    if (fr.converged) {
      ++fr.iterations;
      break;
    }
  }
  finish(problem, it, max_iterations, fr);
  return fr;
}

analytic::ModelParameters lobe_fit_start(const std::string& model_name, const analytic::ModelParameters& start,
                                         const std::vector<std::string>& lobe_keys) {
  analytic::ModelParameters out = start;
  const int lobes = analytic::predicted_lobes(model_name, start);
  for (const std::string& key : lobe_keys) {
    const Key k = parse_key(key);
    const analytic::ParamSpec* spec = spec_of(model_name, k);
    if (k.index < 0 || !spec || !spec->per_lobe || !is_list(*spec)) continue;
    for (int p = 0; p < lobes; ++p) spec->set_entry(out, p, spec->get_entry(start, p));
  }
  return out;
}

std::vector<LobeFit> fit_each_lobe(const sim::ResultFile& result, const std::string& model_name,
                                   const analytic::ModelParameters& start, const std::vector<std::string>& keys,
                                   const Options& options, int max_iterations,
                                   const std::function<void(const std::string&)>& progress) {
  std::vector<int> lobes = options.lobes;
  if (lobes.empty())
    for (int l = 0; l < result.lobes; ++l) lobes.push_back(l);
  std::vector<LobeFit> out;
  const std::vector<std::string> names = result.lobe_names();
  for (int lobe : lobes) {
    Options one = options;
    one.lobes = {lobe};
    const std::string& name = names.at(static_cast<std::size_t>(lobe));
    try {
      const std::vector<std::string> lobe_keys = per_lobe_keys(model_name, keys, lobe);
      out.push_back({lobe, fit_model(result, model_name, lobe_fit_start(model_name, start, lobe_keys), lobe_keys, one,
                                     max_iterations, [&](const std::string& line) {
                                       if (progress) progress(name + " " + line);
                                     })});
    } catch (const Error& e) {
      throw Error(fmt::format("per-lobe fit of {}: {}", name, e.what()));
    }
  }
  return out;
}

}  // namespace fiberlab::compare
