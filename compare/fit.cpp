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

std::vector<int> parse_fit_lobes(const std::vector<std::string>& names, int lobes, const std::string& what) {
  const std::vector<std::string> known = lobe_names(lobes);
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

namespace {
constexpr double kChi2DropTolerance = 1e-2;  // of max(1, chi2/dof): fit.h "Stopping"
constexpr int kExtensions = 3;               // doublings of a step along a valley: fit.h
}  // namespace

const char* outcome_name(FitOutcome o) {
  switch (o) {
    case FitOutcome::Converged: return "converged";
    case FitOutcome::AtBound: return "at a bound";
    case FitOutcome::NotConverged: return "not converged";
  }
  return "not converged";
}

FitResult fit_model(const sim::ResultFile& result, const std::string& model_name,
                    const analytic::ModelParameters& start, const std::vector<std::string>& keys,
                    const Options& options, int max_iterations,
                    const std::function<void(const std::string&)>& progress) {
  if (keys.empty()) throw Error("--fit: no parameters given");
  check_fit_keys(model_name, keys);
  const int n = static_cast<int>(keys.size());
  FitResult fr;
  fr.keys = keys;
  std::vector<double> lo(n), hi(n);
  for (int j = 0; j < n; ++j) {
    std::tie(lo[j], hi[j]) = fit_range(model_name, keys[j]);
    fr.start.push_back(std::clamp(get_parameter(model_name, start, keys[j]), lo[j], hi[j]));
  }
  // Projected Levenberg-Marquardt: every trial point is clamped into the
  // table's ranges (fit_range), so the model is never asked for a value it
  // refuses; derivatives at a bound are one-sided.
  auto project = [&](Eigen::VectorXd x) {
    for (int j = 0; j < n; ++j) x[j] = std::clamp(x[j], lo[j], hi[j]);
    return x;
  };
  for (int l : options.lobes)
    if (l < 0 || l >= result.lobes)
      throw Error(fmt::format("--fit: lobe {} is not in the result (its lobes are 0..{})", l, result.lobes - 1));
  const Selection sel = select_bins(result, options);

  auto params_at = [&](const Eigen::VectorXd& x) {
    analytic::ModelParameters p = start;
    for (int j = 0; j < n; ++j) set_parameter(model_name, p, keys[j], x[j]);
    return p;
  };
  auto to_vector = [](const std::vector<double>& r) {
    return Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(r.data(), static_cast<long>(r.size())));
  };
  auto residuals = [&](const Eigen::VectorXd& x) {
    const auto model = compare::make_model(model_name, params_at(x));
    return to_vector(normalised_residuals(result, sel, predict_result(*model, result), options));
  };
  // Central differences; steps in the keys' units (degrees for angles),
  // sized as fit.h says.
  auto step = [&](int j, double x) {
    const double width = hi[j] - lo[j];
    const double floor = std::isfinite(width) ? 2e-3 * width : 1e-3;
    double h = std::max(2e-2 * std::fabs(x), floor);
    if (std::isfinite(width)) h = std::min(h, 0.1 * width);
    return h;
  };
  // The 2n trial points' predictions are 2n x K independent model
  // evaluations (K incident configurations): one parallel loop over all of
  // them keeps every thread busy (a loop over the n columns leaves threads
  // idle when n is small or not a multiple of them). Each evaluation is
  // deterministic and the residuals are formed afterwards in a fixed order,
  // so J is the same for any thread count.
  const long K = static_cast<long>(result.configs());
  auto jacobian = [&](const Eigen::VectorXd& x, long m) {
    std::vector<Eigen::VectorXd> trial(2 * n, x);
    std::vector<std::unique_ptr<analytic::Model>> models(2 * n);
    for (int j = 0; j < n; ++j) {
      const double h = step(j, x[j]);
      trial[2 * j][j] = std::min(x[j] + h, hi[j]);
      trial[2 * j + 1][j] = std::max(x[j] - h, lo[j]);
      for (int s = 0; s < 2; ++s) models[2 * j + s] = compare::make_model(model_name, params_at(trial[2 * j + s]));
    }
    std::vector<std::vector<std::vector<double>>> predicted(2 * n, std::vector<std::vector<double>>(K));
    std::string error;
#pragma omp parallel for schedule(dynamic)
    for (long t = 0; t < 2 * n * K; ++t) {
      try {
        predicted[t / K][t % K] = predict_config(*models[t / K], result, static_cast<std::size_t>(t % K));
      } catch (const std::exception& e) {
#pragma omp critical
        error = e.what();
      }
    }
    if (!error.empty()) throw Error(error);
    Eigen::MatrixXd J(m, n);
    for (int j = 0; j < n; ++j) {
      const Eigen::VectorXd rp = to_vector(normalised_residuals(result, sel, predicted[2 * j], options));
      const Eigen::VectorXd rm = to_vector(normalised_residuals(result, sel, predicted[2 * j + 1], options));
      // set_parameter may clamp (beta floor): use the actual difference.
      const double dx = get_parameter(model_name, params_at(trial[2 * j]), keys[j]) -
                        get_parameter(model_name, params_at(trial[2 * j + 1]), keys[j]);
      J.col(j) = (rp - rm) / (dx != 0.0 ? dx : 2.0 * step(j, x[j]));
    }
    return J;
  };

  Eigen::VectorXd x(n);
  for (int j = 0; j < n; ++j) x[j] = fr.start[j];
  Eigen::VectorXd r = residuals(x);
  ++fr.evaluations;
  const long m = r.size();
  fr.residuals = static_cast<int>(m);
  fr.dof = static_cast<int>(m) - n;
  if (fr.dof <= 0) throw Error(fmt::format("--fit: {} residuals for {} parameters", m, n));
  fr.chi2_start = r.squaredNorm();
  if (progress)
    progress(fmt::format("fit: {} residuals, {} parameters, start chi2/dof {:.4f}; each iteration costs {} "
                         "model evaluations",
                         m, n, fr.chi2_start / fr.dof, 2 * n + 1));
  double chi2 = fr.chi2_start, lambda = 1e-3;
  Eigen::MatrixXd J = jacobian(x, m);
  fr.evaluations += 2 * n;
  // Parameter errors at x (scaled as the result's): the yardstick of a step.
  auto errors_at = [&](const Eigen::MatrixXd& Jx, double chi2x) {
    const Eigen::MatrixXd cov = (Jx.transpose() * Jx).completeOrthogonalDecomposition().pseudoInverse();
    Eigen::VectorXd e(n);
    for (int j = 0; j < n; ++j) e[j] = std::sqrt(std::max(0.0, cov(j, j)) * std::max(1.0, chi2x / fr.dof));
    return e;
  };
  std::string last_move;  // the last accepted step, for a fit stopped by the cap
  Eigen::VectorXd last_step = Eigen::VectorXd::Zero(n);
  for (fr.iterations = 0; fr.iterations < max_iterations; ++fr.iterations) {
    const Eigen::MatrixXd A = J.transpose() * J;
    Eigen::VectorXd g = J.transpose() * r;
    // Active set: a parameter at a bound whose descent direction points out
    // of its range is held there for this iteration (its row and column
    // decoupled), so the others can still move.
    std::vector<bool> held(n, false);
    for (int j = 0; j < n; ++j)
      held[j] = (x[j] <= lo[j] && g[j] > 0.0) || (x[j] >= hi[j] && g[j] < 0.0);
    const Eigen::VectorXd err = errors_at(J, chi2);
    bool improved = false;
    for (int tries = 0; tries < 12 && !improved; ++tries) {
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
      const Eigen::VectorXd xn = project(x + Ad.ldlt().solve(-gh));
      Eigen::VectorXd step = xn - x;
      const Eigen::VectorXd rn = residuals(xn);
      ++fr.evaluations;
      const double chi2n = rn.squaredNorm();
      if (chi2n < chi2) {
        double drop = chi2 - chi2n;
        const Eigen::VectorXd from = x;
        x = xn;
        r = rn;
        chi2 = chi2n;
        lambda = std::max(lambda / 10.0, 1e-9);
        improved = true;
        // A valley: with large residuals (a model that does not describe the
        // data) J^T J underrates how far chi2 keeps falling, and successive
        // steps are short and point the same way. Then the step is doubled
        // while chi2 keeps falling (at most kExtensions evaluations).
        const double norms = step.norm() * last_step.norm();
        if (norms > 0.0 && step.dot(last_step) > 0.9 * norms) {
          Eigen::VectorXd ahead = step;
          for (int e = 0; e < kExtensions; ++e) {
            ahead *= 2.0;
            const Eigen::VectorXd xe = project(x + ahead);
            if (xe == x) break;
            const Eigen::VectorXd re = residuals(xe);
            ++fr.evaluations;
            const double chi2e = re.squaredNorm();
            if (!(chi2e < chi2)) break;
            drop += chi2 - chi2e;
            x = xe;
            r = re;
            chi2 = chi2e;
          }
          step = x - from;
        }
        last_step = step;
        // The largest step in units of its parameter's error.
        double step_in_errors = 0.0;
        for (int j = 0; j < n; ++j)
          step_in_errors = std::max(step_in_errors, err[j] > 0.0 ? std::fabs(step[j]) / err[j]
                                                                 : (step[j] != 0.0 ? HUGE_VAL : 0.0));
        // A chi2 change of S = max(1, chi2/dof) moves the parameters by one
        // (scaled) error: for a model that does not describe the data
        // (S >> 1) the errors are scaled by sqrt(S). A drop below 1e-2 S is
        // a move of 0.1 error: what is left to gain is far below the errors
        // (fits of wrong models stop there instead of polishing digits).
        const double unit = std::max(1.0, chi2 / fr.dof);
        last_move = fmt::format("chi2 fell by {:.3g} (tolerance {:.3g}), the largest step {:.3g} errors",
                                drop, kChi2DropTolerance * unit, step_in_errors);
        if (drop < kChi2DropTolerance * unit) {
          fr.converged = true;
          fr.stop_reason = fmt::format("chi2 fell by {:.3g} < {:.3g} (1e-2 max(1, chi2/dof))", drop,
                                       kChi2DropTolerance * unit);
        } else if (step_in_errors < 1e-2) {
          fr.converged = true;
          fr.stop_reason = fmt::format("every step below 1% of its parameter's error (largest {:.3g})",
                                       step_in_errors);
        }
      } else {
        lambda *= 10.0;
      }
    }
    if (progress) {
      std::string values;
      for (int j = 0; j < n; ++j) values += fmt::format(" {}={:.6g}", keys[j], x[j]);
      progress(fmt::format("fit: iteration {}, chi2/dof {:.4f}, {} model evaluations,{}", fr.iterations + 1,
                           chi2 / fr.dof, fr.evaluations, values));
    }
    if (!improved) {
      fr.converged = true;  // no downhill step at any damping: at the minimum
      fr.stop_reason = "no step lowers chi2 at any damping (a minimum, to the prediction's resolution)";
      ++fr.iterations;
      break;
    }
    J = jacobian(x, m);
    fr.evaluations += 2 * n;
    if (fr.converged) {
      ++fr.iterations;
      break;
    }
  }
  if (!fr.converged)
    fr.stop_reason = max_iterations == 0 ? "no iterations allowed (max_iterations = 0)"
                                         : fmt::format("stopped at the iteration cap ({}): last step: {}",
                                                       max_iterations, last_move);
  fr.chi2 = chi2;
  const Eigen::MatrixXd cov = (J.transpose() * J).inverse();
  const double scale = std::sqrt(std::max(1.0, fr.per_dof()));
  for (int j = 0; j < n; ++j) {
    fr.value.push_back(x[j]);
    const double e = std::sqrt(std::max(0.0, cov(j, j)));
    fr.error_unscaled.push_back(e);
    fr.error.push_back(e * scale);
    const double tol = 1e-9 * (1.0 + std::fabs(x[j]));
    fr.at_bound.push_back(x[j] <= lo[j] + tol || x[j] >= hi[j] - tol);
  }
  const bool bound = std::find(fr.at_bound.begin(), fr.at_bound.end(), true) != fr.at_bound.end();
  fr.outcome = !fr.converged ? FitOutcome::NotConverged : bound ? FitOutcome::AtBound : FitOutcome::Converged;
  fr.params = params_at(x);
  return fr;
}

std::vector<LobeFit> fit_each_lobe(const sim::ResultFile& result, const std::string& model_name,
                                   const analytic::ModelParameters& start, const std::vector<std::string>& keys,
                                   const Options& options, int max_iterations,
                                   const std::function<void(const std::string&)>& progress) {
  std::vector<int> lobes = options.lobes;
  if (lobes.empty())
    for (int l = 0; l < result.lobes; ++l) lobes.push_back(l);
  std::vector<LobeFit> out;
  for (int lobe : lobes) {
    Options one = options;
    one.lobes = {lobe};
    const std::string name = lobe_name(lobe, result.lobes);
    try {
      out.push_back({lobe, fit_model(result, model_name, start, per_lobe_keys(model_name, keys, lobe), one,
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
