#include "compare/fit.h"

#include <fmt/core.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

#include "common/error.h"
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

void check_fit_key(const std::string& model_name, const std::string& key) {
  const Key k = parse_key(key);
  const analytic::ParamTable& table = analytic::model_info(model_name).params;
  std::string fittable;
  for (const analytic::ParamSpec& s : table)
    if (s.unit != "choice" && s.unit != "integer") fittable += (fittable.empty() ? "" : ", ") + s.key;
  if (analytic::find_param(table, "alpha")) fittable += ", scale_tilt";
  const bool is_list = k.name == "beta_long" || k.name == "beta_azim" || k.name == "alpha" || k.name == "sigma_a";
  const analytic::ParamSpec* spec = analytic::find_param(table, k.name);
  const bool known = k.name == "scale_tilt" ? analytic::find_param(table, "alpha") != nullptr && k.index < 0
                                            : spec && spec->unit != "choice" && spec->unit != "integer" &&
                                                  (k.index < 0 || is_list);
  if (!known)
    throw Error(fmt::format("--fit {}: model {} cannot fit '{}'; fittable keys: {} (lists per lobe as NAME[p])",
                            key, model_name, key, fittable));
  if (k.name == "alpha" && k.index < 0)
    throw Error(fmt::format("--fit alpha: one common shift for every lobe moves R the wrong way; fit "
                            "alpha[p] per lobe (e.g. alpha[0],alpha[1]) or the physical scale_tilt"));
}

FitResult fit_model(const sim::ResultFile& result, const std::string& model_name,
                    const analytic::ModelParams& start, const std::vector<std::string>& keys,
                    const Options& options, int max_iterations,
                    const std::function<void(const std::string&)>& progress) {
  if (keys.empty()) throw Error("--fit: no parameters given");
  for (const std::string& key : keys) check_fit_key(model_name, key);
  const int n = static_cast<int>(keys.size());
  FitResult fr;
  fr.keys = keys;
  for (const std::string& key : keys) fr.start.push_back(get_parameter(start, key));
  const Selection sel = select_bins(result, options);

  auto params_at = [&](const Eigen::VectorXd& x) {
    analytic::ModelParams p = start;
    for (int j = 0; j < n; ++j) set_parameter(p, keys[j], x[j]);
    return p;
  };
  auto residuals = [&](const Eigen::VectorXd& x, bool parallel) {
    const analytic::ModelParams p = params_at(x);
    const auto model = compare::make_model(model_name, p);
    const std::vector<double> r =
        normalised_residuals(result, sel, predict_result(*model, result, parallel), options);
    return Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(r.data(), static_cast<long>(r.size())));
  };
  // Central differences; steps in the keys' units (degrees for angles).
  auto step = [&](int j, double x) {
    return std::max(1e-3 * std::fabs(x), keys[j].rfind("eta", 0) == 0 ? 1e-5 : 1e-3);
  };
  auto jacobian = [&](const Eigen::VectorXd& x, long m) {
    Eigen::MatrixXd J(m, n);
    std::string error;
#pragma omp parallel for schedule(dynamic)
    for (int j = 0; j < n; ++j) {
      try {
        const double h = step(j, x[j]);
        Eigen::VectorXd xp = x, xm = x;
        xp[j] += h;
        xm[j] -= h;
        const Eigen::VectorXd rp = residuals(xp, false), rm = residuals(xm, false);
        // set_parameter may clamp (beta floor): use the actual difference.
        const double dx = get_parameter(params_at(xp), keys[j]) - get_parameter(params_at(xm), keys[j]);
        J.col(j) = (rp - rm) / (dx != 0.0 ? dx : 2.0 * h);
      } catch (const std::exception& e) {
#pragma omp critical
        error = e.what();
      }
    }
    if (!error.empty()) throw Error(error);
    return J;
  };

  Eigen::VectorXd x(n);
  for (int j = 0; j < n; ++j) x[j] = fr.start[j];
  Eigen::VectorXd r = residuals(x, true);
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
  for (fr.iterations = 0; fr.iterations < max_iterations; ++fr.iterations) {
    const Eigen::MatrixXd A = J.transpose() * J;
    const Eigen::VectorXd g = J.transpose() * r;
    bool improved = false;
    for (int tries = 0; tries < 12 && !improved; ++tries) {
      Eigen::MatrixXd Ad = A;
      for (int j = 0; j < n; ++j) Ad(j, j) += lambda * std::max(A(j, j), 1e-12);
      const Eigen::VectorXd dx = Ad.ldlt().solve(-g);
      const Eigen::VectorXd xn = x + dx;
      const Eigen::VectorXd rn = residuals(xn, true);
      ++fr.evaluations;
      const double chi2n = rn.squaredNorm();
      if (chi2n < chi2) {
        const double drop = chi2 - chi2n;
        x = xn;
        r = rn;
        chi2 = chi2n;
        lambda = std::max(lambda / 10.0, 1e-9);
        improved = true;
        // Converged when chi2 moves by less than 1e-3 (absolute: chi2 is a
        // sum of squared normalised residuals, a 1e-3 change is far below
        // its own noise) or the step is tiny against the parameter.
        bool small_step = true;
        for (int j = 0; j < n; ++j)
          if (std::fabs(dx[j]) > 1e-6 * std::max(1.0, std::fabs(x[j]))) small_step = false;
        if (drop < 1e-3 || small_step) fr.converged = true;
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
      break;
    }
    J = jacobian(x, m);
    fr.evaluations += 2 * n;
    if (fr.converged) break;
  }
  fr.chi2 = chi2;
  const Eigen::MatrixXd cov = (J.transpose() * J).inverse();
  const double scale = std::sqrt(std::max(1.0, fr.per_dof()));
  for (int j = 0; j < n; ++j) {
    fr.value.push_back(x[j]);
    const double e = std::sqrt(std::max(0.0, cov(j, j)));
    fr.error_unscaled.push_back(e);
    fr.error.push_back(e * scale);
  }
  fr.params = params_at(x);
  return fr;
}

}  // namespace fiberlab::compare
