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

std::vector<double>* list_of(analytic::ModelParams& p, const std::string& name, double& scale) {
  scale = kPi / 180.0;
  if (name == "beta_long") return &p.beta_long;
  if (name == "beta_azim") return &p.beta_azim;
  if (name == "alpha") return &p.alpha;
  scale = 1.0;
  if (name == "sigma_a") return &p.sigma_a;
  return nullptr;
}

[[noreturn]] void unknown(const std::string& key) {
  throw Error(fmt::format(
      "--fit key '{}' is not fittable (allowed: eta, sigma_a, beta_long, beta_azim, alpha[p], "
      "scale_tilt, k_g, w_c, delta_eta, delta_h_m, eccentricity, or NAME[INDEX] for the lists)",
      key));
}

// Scalar keys of ModelParams that a fit may move (the model's table decides
// which of them a model has).
double* scalar_of(analytic::ModelParams& p, const std::string& name, double& scale) {
  scale = 1.0;
  if (name == "eta") return &p.eta;
  if (name == "k_g") return &p.k_g;
  if (name == "delta_eta") return &p.delta_eta;
  if (name == "delta_h_m") return &p.delta_h_m;
  if (name == "eccentricity") return &p.eccentricity;
  scale = kPi / 180.0;
  if (name == "w_c") return &p.w_c;
  return nullptr;
}

}  // namespace

double get_parameter(const analytic::ModelParams& p0, const std::string& key) {
  analytic::ModelParams p = p0;
  const Key k = parse_key(key);
  if (k.name == "scale_tilt" && k.index < 0) return rad_to_deg(analytic::for_lobe(p.alpha, 1));
  double scale = 1.0;
  if (double* x = scalar_of(p, k.name, scale); x && k.index < 0) return *x / scale;
  std::vector<double>* list = list_of(p, k.name, scale);
  if (!list) unknown(key);
  return analytic::for_lobe(*list, std::max(0, k.index)) / scale;
}

void set_parameter(analytic::ModelParams& p, const std::string& key, double value) {
  const Key k = parse_key(key);
  if (k.name == "scale_tilt" && k.index < 0) {
    p.alpha = analytic::tilt_shifts(deg_to_rad(value));  // SPEC s7's shift rule
    return;
  }
  double scale = 1.0;
  if (double* x = scalar_of(p, k.name, scale); x && k.index < 0) {
    double v = value * scale;
    if (k.name == "eta") v = std::max(v, 1.0 + 1e-9);
    else if (k.name == "eccentricity") v = std::clamp(v, 1e-3, 1.0);
    else v = std::max(v, 0.0);
    *x = v;
    return;
  }
  std::vector<double>* list = list_of(p, k.name, scale);
  if (!list) unknown(key);
  double v = value * scale;
  // Widths and absorption are non-negative; a width of exactly 0 switches
  // d'Eon's model to its delta limits, so keep a positive floor.
  if (k.name == "beta_long" || k.name == "beta_azim") v = std::max(v, deg_to_rad(0.05));
  if (k.name == "sigma_a") v = std::max(v, 0.0);
  if (k.index < 0) {
    if (k.name == "sigma_a") std::fill(list->begin(), list->end(), v);
    else *list = {v};
    return;
  }
  if (list->empty()) list->push_back(v);
  while (static_cast<int>(list->size()) <= k.index) list->push_back(list->back());
  (*list)[k.index] = v;
}

namespace {

// The table entry of a key's name, and whether it is a scalar the table
// reads and writes itself (number_param: ParamSpec::get_number).
const analytic::ParamSpec* spec_of(const std::string& model_name, const Key& k) {
  return analytic::find_param(analytic::model_info(model_name).params, k.name);
}
bool table_scalar(const analytic::ParamSpec* spec) { return spec && spec->get_number && spec->set_number; }
// A per-lobe list whose entry 0 (alpha) is a tilt shift: fitted per lobe or
// through the physical scale_tilt (a model with a list `alpha`).
bool has_alpha_list(const std::string& model_name) {
  const analytic::ParamSpec* a = analytic::find_param(analytic::model_info(model_name).params, "alpha");
  return a && !table_scalar(a);
}

}  // namespace

double get_parameter(const std::string& model_name, const analytic::ModelParams& p, const std::string& key) {
  const Key k = parse_key(key);
  if (const analytic::ParamSpec* spec = spec_of(model_name, k); table_scalar(spec) && k.index < 0)
    return spec->get_number(p);
  return get_parameter(p, key);
}

void set_parameter(const std::string& model_name, analytic::ModelParams& p, const std::string& key,
                   double value) {
  const Key k = parse_key(key);
  if (const analytic::ParamSpec* spec = spec_of(model_name, k); table_scalar(spec) && k.index < 0)
    return spec->set_number(p, value);
  set_parameter(p, key, value);
}

std::pair<double, double> fit_range(const std::string& model_name, const std::string& key) {
  const Key k = parse_key(key);
  if (k.name == "scale_tilt" && has_alpha_list(model_name)) {
    const analytic::ParamSpec* a = analytic::find_param(analytic::model_info(model_name).params, "alpha");
    return {a->fit_min, a->fit_max};
  }
  const analytic::ParamSpec* spec = spec_of(model_name, k);
  if (!spec) throw Error(fmt::format("--fit {}: model {} has no such parameter", key, model_name));
  double lo = spec->fit_min;
  // set_parameter's floor for widths (d'Eon's delta limits at exactly 0).
  if (k.name == "beta_long" || k.name == "beta_azim") lo = std::max(lo, 0.05);
  return {lo, spec->fit_max};
}

std::vector<std::string> free_fit_keys(const std::string& model_name) {
  std::vector<std::string> keys;
  for (const analytic::ParamSpec& s : analytic::model_info(model_name).params) {
    if (!s.free) continue;
    // A per-lobe list of tilt shifts moves through the physical tilt (one
    // number, SPEC s7's rule); any other list as one common value.
    keys.push_back(s.key == "alpha" && !table_scalar(&s) ? "scale_tilt" : s.key);
  }
  return keys;
}

void check_fit_key(const std::string& model_name, const std::string& key) {
  const Key k = parse_key(key);
  const analytic::ParamTable& table = analytic::model_info(model_name).params;
  std::string fittable;
  for (const analytic::ParamSpec& s : table)
    if (s.unit != "choice" && s.unit != "integer") fittable += (fittable.empty() ? "" : ", ") + s.key;
  if (has_alpha_list(model_name)) fittable += ", scale_tilt";
  const analytic::ParamSpec* spec = analytic::find_param(table, k.name);
  const bool is_list = spec && !table_scalar(spec);
  const bool known = k.name == "scale_tilt" ? has_alpha_list(model_name) && k.index < 0
                                            : spec && spec->unit != "choice" && spec->unit != "integer" &&
                                                  (k.index < 0 || is_list);
  if (!known)
    throw Error(fmt::format("--fit {}: model {} cannot fit '{}'; fittable keys: {} (lists per lobe as NAME[p])",
                            key, model_name, key, fittable));
  if (k.name == "alpha" && k.index < 0 && is_list)
    throw Error(fmt::format("--fit alpha: one common shift for every lobe moves R the wrong way; fit "
                            "alpha[p] per lobe (e.g. alpha[0],alpha[1]) or the physical scale_tilt"));
}

void check_fit_keys(const std::string& model_name, const std::vector<std::string>& keys) {
  for (std::size_t i = 0; i < keys.size(); ++i) {
    check_fit_key(model_name, keys[i]);
    const Key b = parse_key(keys[i]);
    for (std::size_t j = 0; j < i; ++j) {
      const Key a = parse_key(keys[j]);
      const bool same = a.name == b.name && (a.index == b.index || a.index < 0 || b.index < 0);
      const bool both_alpha = (a.name == "scale_tilt" && b.name == "alpha") ||
                              (a.name == "alpha" && b.name == "scale_tilt");
      if (same || both_alpha)
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
    if (k.index < 0 && k.name == "scale_tilt" && has_alpha_list(model_name))
      out.push_back(fmt::format("alpha[{}]", lobe));
    else if (k.index < 0 && spec && !table_scalar(spec) && (k.name == "beta_long" || k.name == "beta_azim"))
      out.push_back(fmt::format("{}[{}]", k.name, lobe));
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
                    const analytic::ModelParams& start, const std::vector<std::string>& keys,
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
    analytic::ModelParams p = start;
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
                                   const analytic::ModelParams& start, const std::vector<std::string>& keys,
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
